//! A `Simulation` as the controller of another kernel (the GPU's): with CPU bending off it keeps
//! time and records its steps but bends nothing; switching back recomputes both states.

use glam::Vec3;
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::sim::{SimParams, Simulation, WindParams};

fn fur() -> FurStructure {
    let (mesh, _) = Builtin::Sphere.mesh();
    FurStructure::new(
        mesh,
        &FurParams { layers: 6, length: FurLength::Constant(0.3), direction: GrowthDirection::default() },
    )
    .unwrap()
}

fn windy() -> SimParams {
    SimParams { wind: WindParams { strength: 1.5, ..WindParams::default() }, ..SimParams::default() }
}

#[test]
fn without_cpu_bending_steps_are_recorded_and_nothing_bends() {
    let fur = fur();
    let mut simulation = Simulation::new(&fur, &windy()).unwrap();
    // Construction computes the states at -1/30 s and 0 s.
    assert_eq!(simulation.recent_step_times(), &[-1.0 / 30.0, 0.0]);
    assert_eq!(simulation.steps_taken(), 2);
    simulation.set_cpu_bending(false);
    assert!(!simulation.cpu_bending());
    let frozen = simulation.positions().to_vec();
    // Switching kernels recomputes both states at the next advance, even at the same step.
    simulation.advance_to(0.01);
    assert_eq!(simulation.steps_taken(), 4);
    assert_eq!(simulation.recent_step_times(), &[-1.0 / 30.0, 0.0]);
    // One step per new step index; at most two for a jump; none within a step.
    simulation.advance_to(1.0 / 30.0 + 0.001);
    assert_eq!(simulation.steps_taken(), 5);
    assert_eq!(simulation.recent_step_times(), &[0.0, 1.0 / 30.0]);
    simulation.advance_to(1.0 / 30.0 + 0.02);
    assert_eq!(simulation.steps_taken(), 5);
    simulation.advance_to(2.0);
    assert_eq!(simulation.steps_taken(), 7);
    assert_eq!(simulation.recent_step_times(), &[59.0 / 30.0, 2.0]);
    assert_eq!(simulation.positions(), &frozen[..], "the CPU bends nothing");
}

#[test]
fn cpu_bending_back_on_recomputes_what_a_fresh_simulation_has() {
    let fur = fur();
    let mut simulation = Simulation::new(&fur, &windy()).unwrap();
    simulation.set_cpu_bending(false);
    simulation.advance_to(0.5);
    simulation.touch_begin(fur.positions[10], 0.5).unwrap();
    simulation.touch_drag(fur.positions[10] + Vec3::Y).unwrap();
    simulation.advance_to(1.0);
    simulation.set_cpu_bending(true);
    simulation.advance_to(1.01);
    let mut fresh = Simulation::new(&fur, &windy()).unwrap();
    fresh.touch_begin(fur.positions[10], 0.5).unwrap();
    fresh.touch_drag(fur.positions[10] + Vec3::Y).unwrap();
    fresh.advance_to(1.01);
    assert_eq!(simulation.positions(), fresh.positions());
    assert_ne!(simulation.positions(), &fur.positions[..], "the wind and touch bend the fur");
    // The inputs another kernel reads.
    assert_eq!(simulation.frames().len(), fur.vertex_count());
    assert!(simulation.stability_map().is_none());
    let radius = fur.positions[..fur.vertex_count()].iter().map(|p| p.length()).fold(0.0, f32::max);
    assert!((simulation.bounding_radius() - radius).abs() < 1e-3 * radius, "{}", simulation.bounding_radius());
}
