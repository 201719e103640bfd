//! Length, cut and comb dabs on a running simulation (`Simulation::regroom`, only the reshaped
//! strands) leave it as a simulation built anew on the regrown structure: the same skin planes
//! and triangles and the same states, to the bit, now and over the following steps.

use glam::Vec3;
use pelt_core::groom::{Brush, BrushKind, GroomEditor};
use pelt_core::sim::{Simulation, WindParams};
use pelt_core::{Builtin, FurStructure, Preset};

fn position_bits(simulation: &Simulation) -> Vec<u32> {
    simulation.positions().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect()
}

fn skin_bits(simulation: &Simulation) -> Vec<u32> {
    let skin = simulation.contact_strands().skin;
    skin.iter().flatten().flat_map(|plane| plane.to_array().map(f32::to_bits)).collect()
}

#[test]
fn dabs_in_place_equal_a_rebuilt_simulation_to_the_bit() {
    let preset = Preset::default();
    let (mesh, _) = Builtin::Bunny.mesh();
    let params = preset.fur_params(&mesh);
    let radius = mesh.bounding_sphere().1;
    let mut simulation_params = preset.simulation.clone();
    simulation_params.wind = WindParams { direction: Vec3::X, strength: 0.8, ..simulation_params.wind.clone() };
    // The skin's planes and triangles take part in every step.
    simulation_params.contact.skin = true;
    let mut structure = FurStructure::new_groomed(mesh.clone(), &params, None).unwrap();
    let mut running = Simulation::new(&structure, &simulation_params).unwrap();
    let mut editor = GroomEditor::new(&mesh, None, preset.direction.comb).unwrap();
    let mut time_secs = 0.5;
    running.advance_to(time_secs);
    // Grow lengthens the longest strands (every skin plane is found again), cut and comb leave
    // the longest alone (only the touched strands' are).
    // The last dab shortens the strand keeping the most skin triangles (a concave spot).
    let surface = &running.contact_strands().surface;
    let concave = (0..mesh.vertex_count()).max_by_key(|&j| (surface.strand(j).len(), j)).unwrap();
    assert!(!surface.strand(concave).is_empty(), "the bunny has concave spots");
    for (kind, at) in [
        (BrushKind::Cut, 900),
        (BrushKind::Grow, 100),
        (BrushKind::Comb, 1500),
        (BrushKind::Cut, 60),
        (BrushKind::Cut, concave),
    ] {
        let brush = Brush { kind, radius: 0.15 * radius, strength: 0.6, ..Brush::default() };
        editor.begin_stroke();
        for step in 0..3 {
            editor.stroke_to(&brush, mesh.positions[at] + Vec3::Y * (0.06 * radius * step as f32));
        }
        editor.end_stroke();
        let regrown = FurStructure::new_groomed(mesh.clone(), &params, Some(editor.groom().clone())).unwrap();
        let strands = structure.changed_strands(&regrown);
        // The first comb makes a direction map: the preset's comb, written as a flow per vertex,
        // moves the last bit of many strands' directions.
        let most = if kind == BrushKind::Comb { mesh.vertex_count() } else { mesh.vertex_count() / 4 };
        assert!(!strands.is_empty() && strands.len() < most, "{kind:?}: {} strands", strands.len());
        structure = regrown;
        running.regroom(&structure, &strands).unwrap();
        let mut rebuilt = Simulation::new(&structure, &simulation_params).unwrap();
        rebuilt.advance_to(time_secs);
        assert!(skin_bits(&running) == skin_bits(&rebuilt), "{kind:?}: skin planes");
        assert!(running.contact_strands().surface == rebuilt.contact_strands().surface, "{kind:?}: skin triangles");
        assert!(position_bits(&running) == position_bits(&rebuilt), "{kind:?}: state after the dab");
        for _ in 0..6 {
            time_secs += 1.0 / 30.0;
            running.advance_to(time_secs);
            rebuilt.advance_to(time_secs);
            assert!(position_bits(&running) == position_bits(&rebuilt), "{kind:?}: state at {time_secs} s");
        }
    }
}

#[test]
fn regroom_refuses_another_structure() {
    let preset = Preset::default();
    let (mesh, _) = Builtin::Bunny.mesh();
    let structure = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh)).unwrap();
    let mut simulation = Simulation::new(&structure, &preset.simulation).unwrap();
    let (sphere, _) = Builtin::Sphere.mesh();
    let other = FurStructure::new(sphere.clone(), &preset.fur_params(&sphere)).unwrap();
    assert!(simulation.regroom(&other, &[0]).is_err());
    assert!(simulation.regroom(&structure, &[mesh.vertex_count() as u32]).is_err());
}

/// A simulation made with skin contact off finds no skin planes (most of a dense mesh's setup);
/// turned on later, after a dab reshaped strands, it finds the planes and triangles a simulation
/// made with skin contact on from the regrown structure has; after the next dab on both (a
/// restart, as a new simulation would start) the two step alike, to the bit.
#[test]
fn skin_contact_turned_on_late_equals_it_on_from_the_start() {
    let preset = Preset::default();
    let (mesh, _) = Builtin::Bunny.mesh();
    let params = preset.fur_params(&mesh);
    let radius = mesh.bounding_sphere().1;
    let mut off = preset.simulation.clone();
    off.contact.skin = false;
    off.wind = WindParams { direction: Vec3::X, strength: 0.8, ..off.wind.clone() };
    let on = pelt_core::sim::SimParams { contact: pelt_core::sim::ContactParams { skin: true }, ..off.clone() };
    let mut editor = GroomEditor::new(&mesh, None, preset.direction.comb).unwrap();
    let mut dab = |kind: BrushKind, at: usize| {
        let brush = Brush { kind, radius: 0.15 * radius, strength: 0.6, ..Brush::default() };
        editor.begin_stroke();
        editor.stroke_to(&brush, mesh.positions[at]);
        editor.end_stroke();
        FurStructure::new_groomed(mesh.clone(), &params, Some(editor.groom().clone())).unwrap()
    };
    let structure = FurStructure::new_groomed(mesh.clone(), &params, None).unwrap();
    let mut late = Simulation::new(&structure, &off).unwrap();
    assert!(!late.has_skin_setup(), "skin contact off finds no planes");
    let mut time_secs = 0.5;
    late.advance_to(time_secs);
    // Grow lengthens the longest strands: every strand's skin planes change with their reach.
    let regrown = dab(BrushKind::Grow, 100);
    late.regroom(&regrown, &structure.changed_strands(&regrown)).unwrap();
    late.set_params(&on).unwrap();
    assert!(late.has_skin_setup());
    let mut early = Simulation::new(&regrown, &on).unwrap();
    early.advance_to(time_secs);
    assert!(skin_bits(&late) == skin_bits(&early), "skin planes");
    assert!(late.contact_strands().surface == early.contact_strands().surface, "skin triangles");
    let again = dab(BrushKind::Cut, 60);
    let strands = regrown.changed_strands(&again);
    late.regroom(&again, &strands).unwrap();
    early.regroom(&again, &strands).unwrap();
    assert!(skin_bits(&late) == skin_bits(&early), "skin planes after the second dab");
    assert!(position_bits(&late) == position_bits(&early), "state after the second dab");
    for _ in 0..8 {
        time_secs += 1.0 / 30.0;
        late.advance_to(time_secs);
        early.advance_to(time_secs);
        assert!(position_bits(&late) == position_bits(&early), "state at {time_secs} s");
    }
}
