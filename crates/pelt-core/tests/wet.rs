//! Wet strands under Equation 1 against a closed form that shares no code with the kernel: a
//! straight strand stays in the plane of its rest direction `d` and the force `f`, and segment
//! `k` ends at the angle `b_k = a_0 * prod_{i <= k} (1 - w_i)` from `f`, with `a_0 = angle(d, f)`
//! and `w_i = min(1, |F| * gain * (L - i) / stability)`. A soaked strand's `|F|` is gravity times
//! `1 + added_weight` and its stability `1 - softening` of the dry one's.

use glam::{DVec3, Vec3};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::sim::{SimParams, Simulation};
use pelt_core::wet::WetParams;
use pelt_core::{FurParams, FurStructure, Preset};

/// The tip of a straight strand of `layers` segments of `segment` length from `root` along
/// `direction`, bent by Equation 1 under `force`.
fn closed_form_tip(root: DVec3, direction: DVec3, segment: f64, layers: usize, force: DVec3, stability: f64) -> DVec3 {
    let magnitude = force.length();
    let f = force / magnitude;
    let d = direction.normalize();
    let across = d - f * d.dot(f);
    if across.length() < 1e-9 {
        return root + d * segment * layers as f64;
    }
    let u = across.normalize();
    let a0 = d.dot(f).clamp(-1.0, 1.0).acos();
    let gain = 8.0 / (layers * layers) as f64;
    let mut product = 1.0;
    let mut tip = root;
    for i in 0..layers {
        product *= 1.0 - (magnitude * gain * (layers - i) as f64 / stability).min(1.0);
        let b = a0 * product;
        tip += (f * b.cos() + u * b.sin()) * segment;
    }
    tip
}

fn bunny_fur() -> FurStructure {
    let preset = Preset::default();
    let (mesh, _) = Builtin::Bunny.mesh();
    let params: FurParams = preset.fur_params(&mesh);
    FurStructure::new(mesh, &params).expect("fur")
}

#[test]
fn a_soaked_strand_droops_by_what_equation_1_predicts_with_the_added_weight() {
    let fur = bunny_fur();
    let (v, layers) = (fur.vertex_count(), fur.layers as usize);
    let params = SimParams::default();
    let wet = WetParams { added_weight: 1.5, softening: 0.3, ..WetParams::default() };
    let mut dry = Simulation::new(&fur, &params).expect("simulation");
    let mut soaked = Simulation::new(&fur, &params).expect("simulation");
    soaked.set_wetness(Some(&vec![1.0; v]), &wet).expect("wetness");
    for simulation in [&mut dry, &mut soaked] {
        simulation.advance_to(1.0);
    }
    let gravity = DVec3::NEG_Y * f64::from(params.gravity_strength);
    let stability = f64::from(params.stability);
    let (mut worst, mut droop_dry, mut droop_wet, mut predicted_extra) = (0.0_f64, 0.0, 0.0, 0.0);
    for j in 0..v {
        let root = fur.positions[j].as_dvec3();
        let rest_tip = fur.positions[layers * v + j].as_dvec3();
        let length = f64::from(fur.lengths[j]);
        let direction = rest_tip - root;
        let segment = length / layers as f64;
        let expected_dry = closed_form_tip(root, direction, segment, layers, gravity, stability);
        let expected_wet = closed_form_tip(
            root,
            direction,
            segment,
            layers,
            gravity * (1.0 + f64::from(wet.added_weight)),
            stability * (1.0 - f64::from(wet.softening)),
        );
        let tip_dry = dry.positions()[layers * v + j].as_dvec3();
        let tip_wet = soaked.positions()[layers * v + j].as_dvec3();
        worst = worst.max(tip_dry.distance(expected_dry) / length).max(tip_wet.distance(expected_wet) / length);
        droop_dry += (rest_tip.y - tip_dry.y) / length;
        droop_wet += (rest_tip.y - tip_wet.y) / length;
        predicted_extra += (expected_dry.y - expected_wet.y) / length;
    }
    let n = v as f64;
    eprintln!(
        "droop: mean tip drop {:.4} strand lengths dry, {:.4} soaked (Equation 1 predicts {:.4} more); worst tip {worst:e} lengths off",
        droop_dry / n,
        droop_wet / n,
        predicted_extra / n
    );
    assert!(worst < 2e-4, "a tip is {worst} strand lengths from the closed form");
    assert!((droop_wet - droop_dry) / n > 0.05, "the soaked fur droops visibly more");
    assert!(((droop_wet - droop_dry) - predicted_extra).abs() / n < 1e-4);
}

#[test]
fn drying_to_zero_gives_the_dry_bytes_and_bad_wetness_is_refused() {
    let fur = bunny_fur();
    let v = fur.vertex_count();
    let params = SimParams::default();
    let mut dry = Simulation::new(&fur, &params).expect("simulation");
    let mut dried = Simulation::new(&fur, &params).expect("simulation");
    let wet = WetParams::default();
    dried.set_wetness(Some(&vec![0.7; v]), &wet).expect("wetness");
    dried.advance_to(0.5);
    dried.set_wetness(Some(&vec![0.0; v]), &wet).expect("dry again");
    for simulation in [&mut dry, &mut dried] {
        simulation.advance_to(2.0);
    }
    let bytes = |s: &Simulation| s.positions().iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect::<Vec<_>>();
    assert_eq!(bytes(&dry), bytes(&dried));
    let error = dried.set_wetness(Some(&vec![1.5; v]), &wet).unwrap_err().to_string();
    assert!(error.contains("wetness") && error.contains("between 0 and 1"), "{error}");
    assert!(dried.set_wetness(Some(&[0.5]), &wet).is_err());
}

#[test]
fn bad_wet_input_is_named_by_file_and_key() {
    let preset = Preset::from_toml_str("[wet]\nwetness = 1.5\n", "coat.toml").unwrap_err().to_string();
    assert!(preset.contains("coat.toml") && preset.contains("wet.wetness"), "{preset}");
    let rain = "[[rain]]\nstart_secs = 0.0\nend_secs = 1.0\ndirection = [nan, -1.0, 0.0]\nrate = 1.0\n";
    let error = pelt_core::Scene::from_toml_str(rain, std::path::Path::new("storm.toml")).unwrap_err().to_string();
    assert!(error.contains("storm.toml") && error.contains("rain[0].direction"), "{error}");
    let water = "[[water]]\ntime_secs = 0.0\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 0.0]\n";
    let error = pelt_core::Scene::from_toml_str(water, std::path::Path::new("pond.toml")).unwrap_err().to_string();
    assert!(error.contains("pond.toml") && error.contains("water[0].normal"), "{error}");
    let _ = Vec3::ZERO;
}

/// A sponge on a coat that has been dry for a while wets it, and the water then dries at the
/// preset's rate from that moment: the dry spell is not replayed over it, nor the clock reset.
#[test]
fn a_sponge_after_a_dry_spell_wets_and_dries_from_then() {
    let fur = bunny_fur();
    let mut stepper = pelt_core::sim::FurStepper::new(&fur, &SimParams::default()).expect("stepper");
    let wet = WetParams { drying_per_sec: 0.1, ..WetParams::default() };
    stepper.set_wet(&wet).expect("wet params");
    let rate_hz = f64::from(SimParams::default().rate_hz);
    // One frame of drying at most: 1/30 s at 0.1 a second, within a tick of the step's rounding.
    let most_dried = 0.1 * (1.0 / 30.0 + 1.0 / rate_hz) as f32;
    let centre = fur.mesh.positions[0];
    // Before the first step: the first step does not start the coat over the water.
    stepper.sponge(centre, 0.05, 1.0);
    stepper.advance_to(1.0 / 30.0).expect("first step");
    let first = stepper.wetness().values()[0];
    assert!(first >= 1.0 - most_dried - 1e-6, "wetness under the first sponge {first}");
    stepper.wetness_mut().sponge(fur.mesh.positions.as_slice(), centre, 1e9, 0.0);
    let mut time_secs = 1.0 / 30.0;
    while time_secs < 30.0 {
        time_secs += 1.0 / 30.0;
        stepper.advance_to(time_secs).expect("dry step");
    }
    assert!(stepper.wetness().is_dry());
    stepper.sponge(centre, 0.05, 1.0);
    time_secs += 1.0 / 30.0;
    stepper.advance_to(time_secs).expect("step after the sponge");
    let under = stepper.wetness().values()[0];
    assert!(under >= 1.0 - most_dried - 1e-6, "wetness under the sponge {under}, dried by more than a frame");
    assert!(stepper.simulation().wetness().is_some(), "the simulation sees the water");
}
