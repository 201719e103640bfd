//! The per-strand inputs the GPU simulation computes itself (the inertial force, the touch's
//! weights) against pelt-core's CPU `Simulation`, which shares no WGSL: read back from the GPU's
//! strand state every step, for a still mesh under a touch and for a scripted rigid motion with
//! a touch stroke. Fails, never skips, without an adapter.

use crate::common;

use std::path::Path;

use common::{BROWN_ROOT, BROWN_TIP, Rig, builtin_fur, strand_textures};
use glam::Vec3;
use pelt_core::sim::{FurStepper, Scene, SimParams, Simulation, TouchParams};
use pelt_core::{Builtin, FurStructure};
use pelt_render::{FurStates, GpuFur, GpuSimulation};

const RATE_HZ: f64 = 30.0;

/// The bound on a touch weight (in `[0, 1]`): the GPU's `length` and division may round
/// differently from glam's.
const WEIGHT_BOUND: f32 = 1e-5;
/// The bound on an inertial force, in gravity's units (forces reach 10): absolute plus relative.
const FORCE_BOUND: f32 = 1e-4;

/// Bunny fur simulated on the GPU from a control simulation with its CPU bending off.
struct GpuInputs {
    rig: Rig,
    fur: GpuFur,
    simulation: GpuSimulation,
    vertex_count: usize,
}

impl GpuInputs {
    fn new(structure: &FurStructure) -> Self {
        let rig = Rig::new(16, 16);
        let textures = strand_textures(16, structure.layers, BROWN_ROOT, BROWN_TIP);
        let fur = rig.fur_with_states(structure, &textures, FurStates::Two);
        let simulation = GpuSimulation::new(rig.device(), &fur, structure).expect("GPU simulation");
        Self { rig, fur, simulation, vertex_count: structure.vertex_count() }
    }

    /// Runs the steps `control` took; returns each strand's touch weight and inertial force as
    /// the GPU computed them.
    fn step(&mut self, control: &Simulation) -> (Vec<f32>, Vec<Vec3>) {
        let (device, queue) = (self.rig.device(), self.rig.queue());
        self.simulation.prepare(device, queue, control, &self.fur).expect("prepare");
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        self.simulation.dispatch(&mut encoder, &mut self.fur).expect("dispatch");
        queue.submit([encoder.finish()]);
        let words = self.rig.read_u32s(self.simulation.strand_state());
        let v = self.vertex_count;
        let vec4 = |i: usize| -> [f32; 4] { std::array::from_fn(|c| f32::from_bits(words[i * 4 + c])) };
        let weights = (0..v).map(|j| vec4(j)[3]).collect();
        let forces = (0..v).map(|j| Vec3::from_slice(&vec4(2 * v + j))).collect();
        (weights, forces)
    }
}

/// The CPU's touch weights, one per strand (0 outside the touch).
fn cpu_weights(simulation: &Simulation) -> Vec<f32> {
    let mut weights = vec![0.0; simulation.vertex_count()];
    for &(j, weight) in simulation.strand_inputs().touch_weights {
        weights[j as usize] = weight;
    }
    weights
}

/// Worst touch weight and inertial force differences of one step; the weights only while a
/// touch acts (the GPU keeps a released touch's weights, unused).
fn compare(cpu: &Simulation, weights: &[f32], forces: &[Vec3]) -> (f32, f32) {
    let weight = if cpu.touch().is_some() {
        cpu_weights(cpu).iter().zip(weights).map(|(c, g)| (c - g).abs()).fold(0.0, f32::max)
    } else {
        0.0
    };
    let force = cpu
        .inertial_forces()
        .iter()
        .zip(forces)
        .map(|(c, g)| c.distance(*g) / (1.0 + c.length()))
        .map(|d| if d.is_nan() { f32::INFINITY } else { d })
        .fold(0.0, f32::max);
    (weight, force)
}

/// A still bunny: a touch held, dragged and released with a fade, then a second touch; no
/// inertial force. The weights are weighed on the GPU from the roots of the last step.
#[test]
fn gpu_touch_weights_agree_with_the_cpu_on_a_still_mesh() {
    let structure = builtin_fur(Builtin::Bunny, 8);
    let params = SimParams { touch: TouchParams { strength: 4.0, release_secs: 0.3 }, ..SimParams::default() };
    let mut cpu = Simulation::new(&structure, &params).expect("simulation");
    let mut control = Simulation::new(&structure, &params).expect("simulation");
    control.set_cpu_bending(false);
    let mut gpu = GpuInputs::new(&structure);
    let v = structure.vertex_count();
    let radius = structure.mesh.bounding_sphere().1;
    let (mut worst_weight, mut touched) = (0.0_f32, 0);
    for step in 1..=60 {
        for simulation in [&mut cpu, &mut control] {
            match step {
                5 => simulation.touch_begin(structure.positions[v / 4], 0.4 * radius).expect("touch"),
                6..=20 => {
                    simulation.touch_drag(structure.positions[v / 4] + Vec3::Y * 0.01 * step as f32).expect("drag")
                }
                21 => simulation.touch_end(),
                40 => simulation.touch_begin(structure.positions[3 * v / 4], 0.25 * radius).expect("touch"),
                _ => {}
            }
            simulation.advance_to(f64::from(step) / RATE_HZ);
        }
        if step == 5 || step == 40 {
            assert!(control.touch_began_on_step_roots(), "a still mesh's touch begins on the last step's roots");
        }
        let (weights, forces) = gpu.step(&control);
        let (weight, force) = compare(&cpu, &weights, &forces);
        assert!(weight <= WEIGHT_BOUND, "step {step}: a touch weight is {weight} from the CPU's");
        assert!(force <= FORCE_BOUND, "step {step}: an inertial force is {force} from the CPU's");
        worst_weight = worst_weight.max(weight);
        touched = touched.max(weights.iter().filter(|w| **w > 0.0).count());
    }
    assert!(touched > 20, "the touches reached {touched} strands");
    eprintln!("still mesh: worst touch weight difference {worst_weight:e}");
}

/// The bunny turned and moved by a script's `[[motion]]` keys (accelerating, so the fur feels
/// an inertial force) while a touch stroke crosses it: a stepper stepping every frame, so each
/// touch begins on a step's posed roots and the GPU weighs it. The stroke (`[[stroke]]`, added
/// by the test) starts on a root of the rest mesh.
const MOTION: &str = r#"
[[motion]]
time_secs = 0.0

[[motion]]
time_secs = 1.0
translation = [0.4, 0.1, 0.0]
rotation_deg = [0.0, 50.0, 0.0]
ease = "in_out"

[[motion]]
time_secs = 1.6
translation = [0.0, 0.0, 0.2]
rotation_deg = [10.0, 0.0, 0.0]
ease = "in"
"#;

#[test]
fn gpu_inertia_and_touch_agree_with_the_cpu_under_scripted_motion() {
    let structure = builtin_fur(Builtin::Bunny, 8);
    let params = SimParams { inertia: 0.5, ..SimParams::default() };
    let (root, radius) = (structure.positions[structure.vertex_count() / 4], structure.mesh.bounding_sphere().1);
    let stroke = format!(
        "[[stroke]]\nstart_secs = 0.3\nend_secs = 1.2\nradius = {}\npath = [[{}, {}, {}], [{}, {}, {}]]\n",
        0.4 * radius,
        root.x,
        root.y,
        root.z,
        root.x + 0.2 * radius,
        root.y,
        root.z
    );
    let scene = Scene::from_toml_str(&format!("{stroke}{MOTION}"), Path::new("inputs-test.toml")).expect("script");
    let [mut cpu, mut control] = [(), ()].map(|()| {
        let mut stepper = FurStepper::new(&structure, &params).expect("stepper");
        stepper.set_scene(Some(scene.clone()));
        stepper
    });
    control.simulation_mut().set_cpu_bending(false);
    let mut gpu = GpuInputs::new(&structure);
    let (mut worst_weight, mut worst_force, mut strongest, mut touched) = (0.0_f32, 0.0_f32, 0.0_f32, 0);
    for step in 1..=66 {
        let time_secs = f64::from(step) / RATE_HZ;
        cpu.advance_to(time_secs).expect("advance");
        control.advance_to(time_secs).expect("advance");
        let (weights, forces) = gpu.step(control.simulation());
        let (weight, force) = compare(cpu.simulation(), &weights, &forces);
        assert!(weight <= WEIGHT_BOUND, "step {step}: a touch weight is {weight} from the CPU's");
        assert!(force <= FORCE_BOUND, "step {step}: an inertial force is {force} from the CPU's");
        worst_weight = worst_weight.max(weight);
        worst_force = worst_force.max(force);
        strongest = cpu.simulation().inertial_forces().iter().map(|f| f.length()).fold(strongest, f32::max);
        if cpu.simulation().touch().is_some() {
            assert!(control.simulation().touch_began_on_step_roots(), "step {step}: the touch is weighed on the GPU");
            touched = touched.max(weights.iter().filter(|w| **w > 0.0).count());
        }
    }
    // The motion and the stroke both act, so agreement means something.
    assert!(strongest > 0.05, "the motion's inertial force peaked at {strongest}");
    assert!(touched > 20, "the stroke reached {touched} strands");
    eprintln!("scripted motion: worst touch weight difference {worst_weight:e}, inertial force {worst_force:e}");
}
