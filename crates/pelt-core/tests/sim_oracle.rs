//! The simulation against an oracle that shares no code with it: Equation 1 written out again
//! here in `f64` (acos of a clamped dot product, Rodrigues' rotation of every later node about
//! each node in turn: the paper's literal loop), closed forms where the final angles can be
//! written down, and proptests over straight and curved strands through both kernels
//! (`Simulation`'s batched AVX2 and portable forms, and the scalar `bend_strand`).

use glam::{DVec3, Quat, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::sim::{CpuKernel, Equation, SimParams, Simulation, bend_strand};
use proptest::prelude::*;

/// Below this sine between a segment and the force nothing turns (the documented threshold).
const PARALLEL_SINE: f64 = 1e-7;

/// Equation 1 as documented, literally: root first, at node `k` the angle
/// `acos(clamp(V . f)) * min(1, |F| * gain * (L - k) / stability)` about `V x f`, applied to
/// every node beyond `k`.
fn oracle(root: DVec3, segments: &[DVec3], force: DVec3, stability: f64, gain: f64) -> Vec<DVec3> {
    let layers = segments.len();
    let mut nodes = vec![root];
    for s in segments {
        nodes.push(*nodes.last().unwrap() + *s);
    }
    let magnitude = force.length();
    if magnitude == 0.0 {
        return nodes;
    }
    let f = force / magnitude;
    for k in 0..layers {
        let v = nodes[k + 1] - nodes[k];
        if v.length() == 0.0 {
            continue;
        }
        let v = v / v.length();
        let axis = v.cross(f);
        if axis.length() <= PARALLEL_SINE {
            continue;
        }
        let axis = axis / axis.length();
        let remaining = (layers - k) as f64;
        let theta = v.dot(f).clamp(-1.0, 1.0).acos() * (magnitude * gain * remaining / stability).min(1.0);
        let (sin, cos) = theta.sin_cos();
        let pivot = nodes[k];
        for node in &mut nodes[k + 1..] {
            let p = *node - pivot;
            *node = pivot + p * cos + axis.cross(p) * sin + axis * axis.dot(p) * (1.0 - cos);
        }
    }
    nodes
}

fn pelt_gain(layers: usize) -> f64 {
    8.0 / (layers * layers) as f64
}

/// A seeded stream of numbers in `[-1, 1)` (splitmix64), for strand shapes.
struct Stream(u64);

impl Stream {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / u64::MAX as f64 * 2.0 - 1.0
    }

    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.next(), self.next(), self.next());
            if v.length() > 0.1 && v.length() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

/// A curved strand: each segment turns from the last by up to `curl` radians, lengths vary.
fn curved_strand(stream: &mut Stream, layers: usize, length: f64, curl: f64) -> Vec<DVec3> {
    let mut direction = stream.unit();
    (0..layers)
        .map(|_| {
            let side = direction.cross(stream.unit()).normalize_or_zero();
            direction = (direction + side * (curl * stream.next().abs()).tan()).normalize();
            direction * length / layers as f64 * (1.0 + 0.5 * stream.next())
        })
        .collect()
}

/// Replaces the strands of a grown structure: `shape(j)` gives strand `j`'s segments.
fn with_strands(builtin: Builtin, layers: usize, shape: impl Fn(usize) -> Vec<DVec3>) -> FurStructure {
    let (mesh, _) = builtin.mesh();
    let params =
        FurParams { layers: layers as u32, length: FurLength::Constant(0.1), direction: GrowthDirection::default() };
    let mut fur = FurStructure::new(mesh, &params).unwrap();
    let v = fur.vertex_count();
    for j in 0..v {
        let mut node = fur.positions[j];
        for (k, segment) in shape(j).into_iter().enumerate() {
            node += segment.as_vec3();
            fur.positions[(k + 1) * v + j] = node;
        }
    }
    fur
}

/// Bends every strand of `fur` once with per-strand `forces` and returns the state.
fn simulate(fur: &FurStructure, params: &SimParams, forces: &[Vec3], kernel: CpuKernel) -> Vec<Vec3> {
    let mut sim = Simulation::new(fur, params).unwrap();
    sim.set_cpu_kernel(kernel);
    sim.field_mut().values_mut().copy_from_slice(forces);
    sim.step_at(0.0);
    let mut state = vec![Vec3::ZERO; fur.positions.len()];
    sim.write_lerp(1.0, &mut state);
    state
}

/// The worst distance of any node from the oracle's, in units of its strand's length.
fn worst_error(fur: &FurStructure, state: &[Vec3], params: &SimParams, forces: &[Vec3]) -> f64 {
    let v = fur.vertex_count();
    let layers = fur.layers as usize;
    let gain = match params.equation {
        Equation::Pelt => pelt_gain(layers),
        Equation::Paper => 1.0,
    };
    let mut worst = 0.0f64;
    for j in 0..v {
        let node = |k: usize| fur.positions[k * v + j].as_dvec3();
        let segments: Vec<DVec3> = (0..layers).map(|k| node(k + 1) - node(k)).collect();
        let strand_length: f64 = segments.iter().map(|s| s.length()).sum();
        let force =
            forces[j].as_dvec3() + params.gravity_direction.as_dvec3().normalize() * f64::from(params.gravity_strength);
        let expected = oracle(node(0), &segments, force, f64::from(params.stability), gain);
        for (k, e) in expected.iter().enumerate() {
            let got = state[k * v + j].as_dvec3();
            assert!(got.is_finite(), "strand {j} node {k} is {got}");
            worst = worst.max(got.distance(*e) / strand_length.max(1e-12));
        }
    }
    worst
}

#[test]
fn the_oracle_itself_reproduces_hand_computed_bends() {
    // One segment along X, gravity down, weight 8 * 1 / (1 * 16) = 0.5: half of 90 degrees.
    let tip = oracle(DVec3::ZERO, &[DVec3::X], DVec3::NEG_Y, 16.0, 8.0)[1];
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!(tip.distance(DVec3::new(h, -h, 0.0)) < 1e-12, "{tip}");
    // Two segments, stability 8, gain 8/4: weights min(1, 2 * 2 / 8) = 0.5 then 0.25.
    // The first turn (45 degrees) carries both segments; the second turns the last by a
    // quarter of its remaining 45, to 33.75 degrees from -Y: 56.25 degrees below X.
    let nodes = oracle(DVec3::ZERO, &[DVec3::X, DVec3::X], DVec3::NEG_Y, 8.0, 2.0);
    let first = (nodes[1] - nodes[0]).angle_between(DVec3::X).to_degrees();
    let second = (nodes[2] - nodes[1]).angle_between(DVec3::X).to_degrees();
    // (f64 throughout, so acos is accurate enough here.)
    assert!((first - 45.0).abs() < 1e-9 && (second - 56.25).abs() < 1e-9, "{first} {second}");
}

#[test]
fn a_single_segment_turns_by_its_closed_form() {
    // L = 1: the only segment turns by min(1, |F| * gain / stability) of its angle to the force.
    let h = std::f32::consts::FRAC_1_SQRT_2;
    // 135 degrees to the force, |F| = sqrt 2, weight sqrt 2 * 8 / 12: turns by that share of it.
    let turn = 135f32.to_radians() * (2f32.sqrt() * 8.0 / 12.0);
    let cases = [
        // (force, stability, expected tip of a unit segment along +X from the origin)
        (Vec3::NEG_Y, 16.0, Vec3::new(h, -h, 0.0)),       // weight 1/2
        (Vec3::NEG_Y * 3.0, 48.0, Vec3::new(h, -h, 0.0)), // the magnitude counts
        (Vec3::NEG_Y, 8.0, Vec3::NEG_Y),                  // weight 1: reaches the force
        (Vec3::NEG_Y * 1e9, 1e-6, Vec3::NEG_Y),           // clamped: never past it
        (Vec3::new(-1.0, 1.0, 0.0), 12.0, Vec3::new(turn.cos(), turn.sin(), 0.0)),
        (Vec3::X * 5.0, 1.0, Vec3::X), // along the segment: no turn
        (Vec3::ZERO, 1.0, Vec3::X),    // no force
    ];
    for (i, (force, stability, expected)) in cases.into_iter().enumerate() {
        let mut nodes = [Vec3::ZERO; 2];
        bend_strand(Vec3::ZERO, Quat::IDENTITY, &[Vec3::X], force, stability, &mut nodes);
        assert!(nodes[1].distance(expected) < 2e-6, "case {i}: bend_strand {} vs {expected}", nodes[1]);
        // The batched kernels, on a fur of one-segment strands along +X.
        let fur = with_strands(Builtin::Box, 1, |_| vec![DVec3::X]);
        let params = SimParams { gravity_strength: 0.0, stability, ..SimParams::default() };
        let forces = vec![force; fur.vertex_count()];
        for kernel in [CpuKernel::Avx2Fma, CpuKernel::Portable] {
            let state = simulate(&fur, &params, &forces, kernel);
            let v = fur.vertex_count();
            for j in 0..v {
                let tip = state[v + j] - state[j];
                assert!(tip.distance(expected) < 2e-6, "case {i} {kernel:?} strand {j}: {tip} vs {expected}");
            }
        }
    }
}

#[test]
fn a_uniform_force_on_a_straight_strand_ends_at_the_written_down_angles() {
    // Segment k of a straight strand ends at a_0 * prod_{i <= k} (1 - w_i) from the force,
    // w_i = min(1, |F| * gain * (L - i) / stability), in the plane of strand and force.
    for (layers, angle_deg, magnitude, stability, equation) in [
        (16usize, 90.0f64, 1.0f64, 8.0f64, Equation::Pelt),
        (32, 150.0, 2.5, 3.0, Equation::Pelt),
        (32, 30.0, 1.0, 900.0, Equation::Paper),
        (7, 179.0, 1e6, 1e-3, Equation::Pelt),
        (24, 60.0, 0.2, 40.0, Equation::Paper),
    ] {
        let gain = match equation {
            Equation::Pelt => pelt_gain(layers),
            Equation::Paper => 1.0,
        };
        let a0 = angle_deg.to_radians();
        let f = DVec3::NEG_Y;
        let u = DVec3::new(a0.sin(), -a0.cos(), 0.0); // angle a0 from -Y
        let fur = with_strands(Builtin::Box, layers, |_| vec![u * (0.3 / layers as f64); layers]);
        let params = SimParams {
            gravity_strength: magnitude as f32,
            stability: stability as f32,
            equation,
            ..SimParams::default()
        };
        let zero = vec![Vec3::ZERO; fur.vertex_count()];
        let v = fur.vertex_count();
        for kernel in [CpuKernel::Avx2Fma, CpuKernel::Portable] {
            let state = simulate(&fur, &params, &zero, kernel);
            let mut expected = a0;
            for k in 0..layers {
                expected *= 1.0 - (magnitude * gain * (layers - k) as f64 / stability).min(1.0);
                for j in (0..v).step_by(37) {
                    let d = (state[(k + 1) * v + j] - state[k * v + j]).as_dvec3();
                    let got = d.cross(f).length().atan2(d.dot(f));
                    assert!(
                        (got - expected).abs() < 2e-5,
                        "L={layers} {angle_deg} deg |F|={magnitude} s={stability} {equation:?} {kernel:?}: segment {k} at {got}, expected {expected}"
                    );
                    assert!(d.z.abs() < 1e-6, "left the plane of strand and force");
                }
            }
        }
    }
}

#[test]
fn paper_equation_is_pelts_with_the_converted_stability() {
    let layers = 16;
    let fur = with_strands(Builtin::Bunny, layers, |j| curved_strand(&mut Stream(j as u64), layers, 0.2, 0.3));
    let forces: Vec<Vec3> = (0..fur.vertex_count()).map(|j| Vec3::new((j % 5) as f32 * 0.4, 0.0, 0.3)).collect();
    let pelt = SimParams { stability: 8.0, ..SimParams::default() };
    let paper = SimParams {
        stability: Equation::paper_stability_from_pelt(8.0, layers as u32),
        equation: Equation::Paper,
        ..SimParams::default()
    };
    assert_eq!(paper.stability, 256.0);
    let a = simulate(&fur, &pelt, &forces, CpuKernel::Auto);
    let b = simulate(&fur, &paper, &forces, CpuKernel::Auto);
    let worst = a.iter().zip(&b).map(|(p, q)| p.distance(*q)).fold(0.0, f32::max);
    assert!(worst < 1e-5, "{worst}");
    // And the paper's form is not Pelt's at the same stability.
    let same = SimParams { equation: Equation::Paper, ..pelt.clone() };
    let c = simulate(&fur, &same, &forces, CpuKernel::Auto);
    assert!(a.iter().zip(&c).any(|(p, q)| p.distance(*q) > 1e-2));
    assert!(toml::from_str::<SimParams>("equation = \"paper\"").unwrap().equation == Equation::Paper);
    assert!(toml::from_str::<SimParams>("equation = \"papers\"").is_err());
}

fn kernels_match_the_oracle(fur: &FurStructure, params: &SimParams, forces: &[Vec3], tolerance: f64) {
    let mut states = Vec::new();
    for kernel in [CpuKernel::Avx2Fma, CpuKernel::Portable] {
        let state = simulate(fur, params, forces, kernel);
        let worst = worst_error(fur, &state, params, forces);
        assert!(worst < tolerance, "{kernel:?}: worst node error {worst:e} of the strand length");
        states.push(state);
    }
    assert!(states[0] == states[1], "AVX2 and portable kernels differ");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn curved_strands_match_the_oracle(
        layers in 1usize..40,
        seed in any::<u64>(),
        curl in 0.0f64..0.6,
        force_log10 in -3.0f32..4.0,
        stability_log10 in -2.0f32..3.0,
        paper in any::<bool>(),
    ) {
        let fur = with_strands(Builtin::Box, layers, |j| curved_strand(&mut Stream(seed ^ j as u64), layers, 0.3, curl));
        let mut stream = Stream(seed.rotate_left(17));
        let forces: Vec<Vec3> = (0..fur.vertex_count())
            .map(|_| (stream.unit() * 10f64.powf(f64::from(force_log10) + stream.next())).as_vec3())
            .collect();
        let equation = if paper { Equation::Paper } else { Equation::Pelt };
        let stability = 10f32.powf(stability_log10) * if paper { (layers * layers) as f32 / 8.0 } else { 1.0 };
        let params = SimParams { gravity_strength: 0.0, stability, equation, ..SimParams::default() };
        kernels_match_the_oracle(&fur, &params, &forces, 2e-5);
        // The scalar bend_strand (Pelt's equation only) against the same oracle.
        if !paper {
            let v = fur.vertex_count();
            let mut nodes = vec![Vec3::ZERO; layers + 1];
            for j in (0..v).step_by(13) {
                let segments: Vec<Vec3> = (0..layers).map(|k| fur.positions[(k + 1) * v + j] - fur.positions[k * v + j]).collect();
                bend_strand(fur.positions[j], Quat::IDENTITY, &segments, forces[j], stability, &mut nodes);
                let doubles: Vec<DVec3> = segments.iter().map(|s| s.as_dvec3()).collect();
                let expected = oracle(fur.positions[j].as_dvec3(), &doubles, forces[j].as_dvec3(), f64::from(stability), pelt_gain(layers));
                let length: f64 = doubles.iter().map(|s| s.length()).sum();
                for (got, e) in nodes.iter().zip(&expected) {
                    prop_assert!(got.as_dvec3().distance(*e) < 2e-5 * length, "{} vs {}", got, e);
                }
            }
        }
    }

    #[test]
    fn straight_strands_match_the_oracle(
        layers in 1usize..40,
        seed in any::<u64>(),
        force_log10 in -3.0f32..6.0,
        stability_log10 in -3.0f32..4.0,
        gravity in 0.0f32..3.0,
    ) {
        let (mesh, _) = Builtin::Sphere.mesh();
        let direction = GrowthDirection { random_angle_rad: 0.5, seed, ..GrowthDirection::default() };
        let fur = FurStructure::new(mesh, &FurParams { layers: layers as u32, length: FurLength::Constant(0.4), direction }).unwrap();
        let mut stream = Stream(seed);
        let forces: Vec<Vec3> = (0..fur.vertex_count())
            .map(|_| (stream.unit() * 10f64.powf(f64::from(force_log10) + stream.next())).as_vec3())
            .collect();
        let params = SimParams { gravity_strength: gravity, stability: 10f32.powf(stability_log10), ..SimParams::default() };
        kernels_match_the_oracle(&fur, &params, &forces, 2e-5);
    }
}

#[test]
fn grown_fur_takes_the_straight_form_and_curved_fur_the_general_one() {
    let (mesh, _) = Builtin::Bunny.mesh();
    let direction = GrowthDirection { random_angle_rad: 0.4, seed: 3, ..GrowthDirection::default() };
    let fur = FurStructure::new(mesh, &FurParams { layers: 32, length: FurLength::Constant(0.5), direction }).unwrap();
    assert_eq!(Simulation::new(&fur, &SimParams::default()).unwrap().straight_share(), 1.0);
    let curved = with_strands(Builtin::Bunny, 8, |j| curved_strand(&mut Stream(j as u64), 8, 0.3, 0.2));
    assert_eq!(Simulation::new(&curved, &SimParams::default()).unwrap().straight_share(), 0.0);
}

#[test]
fn avx2_is_used_where_the_cpu_has_it() {
    let fur = with_strands(Builtin::Box, 4, |_| vec![DVec3::Y * 0.1; 4]);
    let mut sim = Simulation::new(&fur, &SimParams::default()).unwrap();
    let available = CpuKernel::avx2_fma_available();
    assert_eq!(sim.cpu_kernel() == CpuKernel::Avx2Fma, available);
    sim.set_cpu_kernel(CpuKernel::Portable);
    assert_eq!(sim.cpu_kernel(), CpuKernel::Portable);
    if cfg!(target_arch = "x86_64") && std::env::var_os("PELT_EXPECT_AVX2").is_some() {
        assert!(available, "PELT_EXPECT_AVX2 is set but this CPU lacks AVX2 + FMA");
    }
}
