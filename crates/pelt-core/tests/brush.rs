//! Brushes: each dab checked against values computed here (in f64, from the falloff formulas
//! written out again), undo and redo to the byte, mirror symmetry, combing, posed hits.

use glam::Vec3;
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::groom::{Axis, Brush, BrushKind, Falloff, Groom, GroomEditor, GroomMap, rest_point};
use pelt_core::mesh::Mesh;
use pelt_core::{Builtin, sim};

fn plane() -> Mesh {
    Builtin::Plane.mesh().0
}

/// The falloff formulas, written out independently of the brush code.
fn expected_weight(falloff: Falloff, strength: f64, distance: f64, radius: f64) -> Option<f64> {
    if distance >= radius {
        return None;
    }
    let t = distance / radius;
    let shape = match falloff {
        Falloff::Constant => 1.0,
        Falloff::Linear => 1.0 - t,
        Falloff::Smooth => 1.0 - (3.0 * t * t - 2.0 * t * t * t),
    };
    Some(strength * shape)
}

fn distance64(a: Vec3, b: Vec3) -> f64 {
    let d = [a.x as f64 - b.x as f64, a.y as f64 - b.y as f64, a.z as f64 - b.z as f64];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// A groom whose every map varies over the mesh (deterministic, in range).
fn varied(mesh: &Mesh) -> Groom {
    let v = mesh.vertex_count();
    let wave = |j: usize, k: f32| 0.5 + 0.4 * ((j as f32) * k).sin();
    Groom {
        length: Some((0..v).map(|j| wave(j, 0.37) * 2.0).collect()),
        density: Some((0..v).map(|j| wave(j, 0.11)).collect()),
        direction: None,
        clump: Some((0..v).map(|j| wave(j, 0.23)).collect()),
        tint: Some((0..v).map(|j| Vec3::new(wave(j, 0.3), wave(j, 0.5), wave(j, 0.7))).collect()),
    }
}

#[test]
fn a_dab_changes_only_the_vertices_in_reach_by_its_falloff() {
    let mesh = plane();
    let before = varied(&mesh);
    let centre = Vec3::new(0.3, 0.0, -0.2);
    let radius = 0.45;
    for falloff in Falloff::ALL {
        for kind in [BrushKind::Grow, BrushKind::Shorten, BrushKind::Cut, BrushKind::Density, BrushKind::Tint] {
            let brush = Brush {
                kind,
                radius,
                strength: 0.8,
                falloff,
                value: 0.1,
                colour: Vec3::new(1.0, 0.0, 0.25),
                ..Brush::default()
            };
            let mut editor = GroomEditor::new(&mesh, Some(before.clone()), Vec3::ZERO).unwrap();
            assert_eq!(editor.dab(&brush, centre, Vec3::ZERO), Some(kind.target(GroomMap::Length)));
            let after = editor.groom();
            let mut in_reach = 0;
            for (j, &p) in mesh.positions.iter().enumerate() {
                let weight = expected_weight(falloff, 0.8, distance64(p, centre), radius as f64);
                let check = |old: f32, new: f32, expected: f64| match weight {
                    None => {
                        assert_eq!(old.to_bits(), new.to_bits(), "{kind:?} {falloff:?}: vertex {j} is out of reach")
                    }
                    Some(_) => assert!(
                        (new as f64 - expected).abs() < 1e-5,
                        "{kind:?} {falloff:?}: vertex {j}: {new} != {expected}"
                    ),
                };
                let w = weight.unwrap_or(0.0);
                in_reach += usize::from(weight.is_some());
                let (l0, l1) = (before.length.as_ref().unwrap()[j], after.length.as_ref().unwrap()[j]);
                let (d0, d1) = (before.density.as_ref().unwrap()[j], after.density.as_ref().unwrap()[j]);
                let (t0, t1) = (before.tint.as_ref().unwrap()[j], after.tint.as_ref().unwrap()[j]);
                match kind {
                    BrushKind::Grow => check(l0, l1, l0 as f64 + 0.25 * w),
                    BrushKind::Shorten => check(l0, l1, (l0 as f64 - 0.25 * w).max(0.0)),
                    BrushKind::Cut => check(l0, l1, l0 as f64 * (1.0 - w)),
                    BrushKind::Density => check(d0, d1, d0 as f64 + (0.1 - d0 as f64) * w),
                    BrushKind::Tint => {
                        for (c, target) in [(0, 1.0), (1, 0.0), (2, 0.25)] {
                            check(t0[c], t1[c], t0[c] as f64 + (target - t0[c] as f64) * w);
                        }
                    }
                    _ => unreachable!(),
                }
                // The maps the brush does not paint stay as they were, to the bit.
                if kind.target(GroomMap::Length) != GroomMap::Length {
                    assert_eq!(l0.to_bits(), l1.to_bits());
                }
                assert_eq!(before.clump, after.clump);
            }
            assert!(in_reach > 10, "the dab reached {in_reach} vertices");
        }
    }
}

#[test]
fn smooth_pulls_toward_the_neighbours_mean_and_erase_toward_the_preset() {
    let mesh = plane();
    let before = varied(&mesh);
    let centre = Vec3::new(-0.2, 0.0, 0.1);
    let brush =
        Brush { radius: 0.5, strength: 0.6, falloff: Falloff::Linear, map: GroomMap::Clump, ..Brush::default() };
    let mut neighbours = vec![Vec::new(); mesh.vertex_count()];
    for &[a, b] in &mesh.edges {
        neighbours[a as usize].push(b as usize);
        neighbours[b as usize].push(a as usize);
    }
    let old = before.clump.clone().unwrap();
    for kind in [BrushKind::Smooth, BrushKind::Erase] {
        let mut editor = GroomEditor::new(&mesh, Some(before.clone()), Vec3::ZERO).unwrap();
        editor.dab(&Brush { kind, ..brush }, centre, Vec3::ZERO);
        let new = editor.groom().clump.as_ref().unwrap();
        for (j, &p) in mesh.positions.iter().enumerate() {
            let Some(w) = expected_weight(Falloff::Linear, 0.6, distance64(p, centre), 0.5) else {
                assert_eq!(old[j].to_bits(), new[j].to_bits());
                continue;
            };
            let target = match kind {
                BrushKind::Smooth => {
                    neighbours[j].iter().map(|&k| old[k] as f64).sum::<f64>() / neighbours[j].len() as f64
                }
                _ => 0.0,
            };
            let expected = old[j] as f64 + (target - old[j] as f64) * w;
            assert!((new[j] as f64 - expected).abs() < 1e-5, "{kind:?}: vertex {j}: {} != {expected}", new[j]);
        }
    }
    // Erasing or smoothing a map the groom does not have leaves it absent.
    let mut editor = GroomEditor::new(&mesh, None, Vec3::ZERO).unwrap();
    for kind in [BrushKind::Smooth, BrushKind::Erase] {
        assert_eq!(editor.dab(&Brush { kind, ..brush }, centre, Vec3::ZERO), None);
    }
    assert!(editor.groom().is_uniform());
}

#[test]
fn undo_restores_the_exact_bytes_and_redo_reapplies_them() {
    let mesh = Builtin::Bunny.mesh().0;
    let bytes = |g: &Groom| g.to_file_bytes(&mesh).unwrap();
    let centre = mesh.positions[100];
    let mut editor = GroomEditor::new(&mesh, None, Vec3::NEG_Y).unwrap();
    let start = bytes(editor.groom());
    let strokes = [
        Brush { kind: BrushKind::Cut, radius: 0.05, strength: 1.0, ..Brush::default() },
        Brush { kind: BrushKind::Comb, radius: 0.05, strength: 0.7, ..Brush::default() },
        Brush {
            kind: BrushKind::Tint,
            radius: 0.04,
            strength: 0.3,
            colour: Vec3::new(0.9, 0.5, 0.2),
            ..Brush::default()
        },
        Brush { kind: BrushKind::Smooth, radius: 0.08, strength: 1.0, map: GroomMap::Length, ..Brush::default() },
    ];
    let mut after_each = vec![start.clone()];
    for (i, brush) in strokes.iter().enumerate() {
        editor.begin_stroke();
        for step in 0..6 {
            editor.stroke_to(brush, centre + Vec3::new(0.01 * step as f32, 0.003 * i as f32, 0.0));
        }
        assert!(editor.end_stroke(), "stroke {i} changed nothing");
        after_each.push(bytes(editor.groom()));
    }
    assert_eq!(editor.history(), (4, 0));
    for i in (0..strokes.len()).rev() {
        editor.undo().unwrap();
        assert_eq!(bytes(editor.groom()), after_each[i], "undo to before stroke {i}");
    }
    assert!(editor.groom().is_uniform(), "maps the strokes created are absent again");
    assert_eq!(editor.undo(), None);
    for (i, expected) in after_each.iter().enumerate().skip(1) {
        editor.redo().unwrap();
        assert_eq!(&bytes(editor.groom()), expected, "redo of stroke {}", i - 1);
    }
    assert_eq!(editor.redo(), None);
    // A new stroke after an undo drops what could be redone.
    editor.undo();
    editor.dab(&Brush { kind: BrushKind::Grow, ..strokes[0] }, centre, Vec3::ZERO);
    assert_eq!(editor.history(), (4, 0));
}

/// The vertex nearest to `p` (the oracle's own search).
fn nearest(positions: &[Vec3], p: Vec3) -> usize {
    (0..positions.len()).min_by(|&a, &b| positions[a].distance(p).total_cmp(&positions[b].distance(p))).unwrap()
}

#[test]
fn a_mirrored_stroke_grooms_both_sides_alike() {
    // The box is symmetric across x = 0: every vertex has a mirror image among its vertices.
    let mesh = Builtin::Box.mesh().0;
    let mirror_of: Vec<usize> = mesh.positions.iter().map(|&p| nearest(&mesh.positions, Axis::X.reflect(p))).collect();
    for (j, &m) in mirror_of.iter().enumerate() {
        assert!(mesh.positions[m].distance(Axis::X.reflect(mesh.positions[j])) < 1e-5);
    }
    let comb = Vec3::NEG_Y;
    let mut editor = GroomEditor::new(&mesh, None, comb).unwrap();
    let on_top = |x: f32, z: f32| Vec3::new(x, 1.0, z);
    for kind in [BrushKind::Cut, BrushKind::Grow, BrushKind::Comb] {
        let brush = Brush { kind, radius: 0.5, strength: 0.7, mirror: Some(Axis::X), ..Brush::default() };
        editor.begin_stroke();
        // A stroke across the top face from x = 0.2 to 0.8, and one crossing the plane.
        for step in 0..=12 {
            editor.stroke_to(&brush, on_top(0.2 + 0.05 * step as f32, 0.3 - 0.04 * step as f32));
        }
        editor.end_stroke();
    }
    let groom = editor.groom().clone();
    let length = groom.length.as_ref().unwrap();
    let params = FurParams {
        layers: 4,
        length: FurLength::Constant(0.2),
        direction: GrowthDirection { comb, comb_blend: 0.6, ..GrowthDirection::default() },
    };
    let fur = FurStructure::new_groomed(mesh.clone(), &params, Some(groom.clone())).unwrap();
    let mut changed_left = 0;
    for (j, &m) in mirror_of.iter().enumerate() {
        assert!((length[j] - length[m]).abs() < 1e-4, "length {j} {} vs its mirror {m} {}", length[j], length[m]);
        let (d, dm) = (fur.directions[j], Axis::X.reflect(fur.directions[m]));
        assert!(d.angle_between(dm) < 1e-3, "direction {j} {d} vs its mirror's reflection {dm}");
        changed_left += usize::from(mesh.positions[j].x < -0.1 && length[j] != 1.0);
    }
    assert!(changed_left > 3, "the mirror reached {changed_left} vertices on the other side");
}

#[test]
fn the_comb_lays_the_fur_along_the_stroke() {
    let mesh = plane();
    let params = FurParams {
        layers: 4,
        length: FurLength::Constant(0.1),
        direction: GrowthDirection { comb: Vec3::Z, comb_blend: 0.8, ..GrowthDirection::default() },
    };
    let brush =
        Brush { kind: BrushKind::Comb, radius: 0.3, strength: 1.0, falloff: Falloff::Constant, ..Brush::default() };
    let mut editor = GroomEditor::new(&mesh, None, params.direction.comb).unwrap();
    editor.begin_stroke();
    for step in 0..=10 {
        editor.stroke_to(&brush, Vec3::new(-0.5 + 0.1 * step as f32, 0.0, 0.0));
    }
    editor.end_stroke();
    let fur = FurStructure::new_groomed(mesh.clone(), &params, Some(editor.groom().clone())).unwrap();
    let uniform = FurStructure::new(mesh.clone(), &params).unwrap();
    let (mut combed, mut untouched) = (0, 0);
    for (j, &p) in mesh.positions.iter().enumerate() {
        let along = fur.directions[j] - Vec3::Y * fur.directions[j].y;
        // In reach of a dab (centres every 0.1 from x = -0.4 to 0.5 on z = 0).
        let reached = (-0.4..=0.5).contains(&p.x) && p.z.abs() < 0.3 - 1e-3;
        let far = p.x < -0.75 || p.x > 0.85 || p.z.abs() > 0.35;
        if reached {
            assert!(along.angle_between(Vec3::X) < 0.5f32.to_radians(), "vertex {j} at {p}: {along}");
            combed += 1;
        } else if far {
            assert!(
                fur.directions[j].angle_between(uniform.directions[j]) < 1e-4,
                "vertex {j} at {p} out of reach turned"
            );
            untouched += 1;
        }
    }
    assert!(combed > 10 && untouched > 10, "{combed} combed, {untouched} untouched");
    // An absent direction map stands for the preset's comb: painting elsewhere keeps it.
    let flows = editor.groom().direction.as_ref().unwrap();
    let far_vertex = nearest(&mesh.positions, Vec3::new(0.0, 0.0, 0.9));
    assert!((flows[far_vertex].length() - 1.0).abs() < 1e-5, "{}", flows[far_vertex]);
}

#[test]
fn a_posed_hit_lands_on_the_rest_surface() {
    let mesh = Builtin::Bunny.mesh().0;
    // A pose: the rest mesh turned and moved.
    let turn = glam::Quat::from_rotation_y(0.7);
    let posed: Vec<Vec3> = mesh.positions.iter().map(|&p| turn * p + Vec3::new(0.3, -0.1, 0.2)).collect();
    let triangle = mesh.triangles.iter().position(|t| t.contains(&10)).unwrap();
    let corners = mesh.triangles[triangle].map(|j| posed[j as usize]);
    let aim = (corners[0] + corners[1] + corners[2]) / 3.0;
    let origin = aim + Vec3::new(0.0, 0.0, 5.0);
    let hit = sim::pick::pick(&posed, &mesh.triangles, origin, aim - origin).unwrap();
    let rest = rest_point(&mesh, hit.triangle, hit.barycentric).unwrap();
    let [a, b, c] = mesh.triangles[hit.triangle as usize].map(|j| mesh.positions[j as usize]);
    let expected = a * hit.barycentric.x + b * hit.barycentric.y + c * hit.barycentric.z;
    assert!(rest.distance(expected) < 1e-6);
    // The hit point, taken back through the pose, is the rest point.
    let back = turn.inverse() * (hit.point - Vec3::new(0.3, -0.1, 0.2));
    assert!(back.distance(rest) < 1e-4, "{back} vs {rest}");
    assert_eq!(rest_point(&mesh, mesh.triangles.len() as u32, Vec3::ONE), None);
}
