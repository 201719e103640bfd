//! `pelt stats`: the paper's Table 2 for any mesh, measured rather than quoted.
//!
//! Grows the unified structure on the mesh and prints its counts and GPU bytes next to the
//! separated structure of Lengyel et al. with 2-face fins and with `N`-face fins.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;

use anyhow::Context as _;
use pelt_core::anim::Rig;
use pelt_core::fur::{Footprint, FurLength, MAX_LAYERS};
use pelt_core::groom::Groom;
use pelt_core::{Builtin, FurParams, FurStructure, GrowthDirection, MeshReport, Preset, SeparatedStructure};

use crate::format::thousands;
use crate::mesh_args::MeshArgs;

/// Arguments of `pelt stats`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Shells above the base, `L` (the paper's tables use 16).
    #[arg(long, default_value_t = 16)]
    pub layers: u32,
    /// Faces per fin of the separated structure it is compared against, `N` (the paper: 30).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub fin_faces: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// A preset whose `[groom]` says where fur grows: faces on bald triangles and edges are not
    /// drawn, so not counted (its other values leave the counts as they are).
    #[arg(long, value_name = "FILE")]
    pub preset: Option<PathBuf>,
}

/// The numbers `pelt stats` reports.
#[derive(Debug, serde::Serialize)]
pub struct Stats {
    pub mesh: MeshReport,
    pub layers: u32,
    /// The preset whose groom decided the faces drawn.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub groom: Option<String>,
    /// `N`, faces per fin of the second separated structure.
    pub fin_faces: u32,
    /// The JSON names structures as `pelt bench --json` does (`unified`, `separated2`;
    /// `separated_n` has `fin_faces` faces per fin): see "JSON keys" in BENCHMARKS.md.
    pub unified: Footprint,
    #[serde(rename = "separated2")]
    pub separated_two_face_fins: Footprint,
    #[serde(rename = "separated_n")]
    pub separated_n_face_fins: Footprint,
    /// How much the unified structure saves, in percent of each separated one.
    #[serde(flatten)]
    pub savings: Savings,
    /// Skins, joints and animations, for a file that moves.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<Motion>,
}

/// What moves in a glTF file.
#[derive(Debug, serde::Serialize)]
pub struct Motion {
    pub skins: Vec<SkinRow>,
    pub nodes: usize,
    pub morph_targets: usize,
    pub animations: Vec<AnimationRow>,
    /// What was wrong with the skins and animations and how it was handled.
    pub notes: Vec<String>,
}

#[derive(Debug, serde::Serialize)]
pub struct SkinRow {
    pub name: Option<String>,
    pub joints: usize,
}

#[derive(Debug, serde::Serialize)]
pub struct AnimationRow {
    pub name: Option<String>,
    pub duration_secs: f32,
    pub channels: usize,
}

impl Motion {
    /// The report rows of `rig`.
    #[must_use]
    pub fn of(rig: &Rig) -> Self {
        Self {
            skins: rig.skins().iter().map(|s| SkinRow { name: s.name.clone(), joints: s.joints }).collect(),
            nodes: rig.nodes().len(),
            morph_targets: rig.morph_target_count(),
            animations: rig
                .animations()
                .iter()
                .map(|a| AnimationRow {
                    name: a.name.clone(),
                    duration_secs: a.duration_secs(),
                    channels: a.channels.len(),
                })
                .collect(),
            notes: rig.report().to_vec(),
        }
    }
}

/// Savings of the unified structure, in percent of a separated one.
#[derive(Debug, serde::Serialize)]
pub struct Savings {
    #[serde(rename = "savings_vs_2_percent")]
    pub vertices_vs_two_face_fins_percent: f64,
    #[serde(rename = "savings_vs_n_percent")]
    pub vertices_vs_n_face_fins_percent: f64,
    #[serde(rename = "bytes_savings_vs_2_percent")]
    pub gpu_bytes_vs_two_face_fins_percent: f64,
    #[serde(rename = "bytes_savings_vs_n_percent")]
    pub gpu_bytes_vs_n_face_fins_percent: f64,
}

/// The paper's printed Table 2 row for its Box: (shared vertices, separated with 2-face fins,
/// separated with 30-face fins), at 16 layers.
const PAPER_BOX: (u64, u64, u64) = (5_032, 6_796, 31_492);

pub fn run(args: &Args) -> anyhow::Result<()> {
    let pelt_core::Stage { fur_mesh: mesh, report, rig, .. } = args.mesh.stage(Builtin::Box, &[])?;
    let groom = match &args.preset {
        Some(path) => Preset::load(path)?.groom(&mesh, &args.mesh.source(Builtin::Box)?.name())?,
        None => None,
    };
    let groomed_by = groom.as_ref().filter(|g| !g.is_uniform()).and(args.preset.as_ref());
    let mut stats = measure(mesh, report, args.layers, args.fin_faces, groom)?;
    stats.groom = groomed_by.map(|path| path.display().to_string());
    stats.motion = rig.as_ref().map(Motion::of);
    let text = if args.json { serde_json::to_string_pretty(&stats)? + "\n" } else { table(&stats) };
    write_stdout(&text)
}

/// Writes to stdout; a closed pipe (`pelt stats | head`) is not an error.
fn write_stdout(text: &str) -> anyhow::Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        result => result.context("cannot write the report to stdout"),
    }
}

/// Grows the unified structure on `mesh` (with `groom`'s bald regions left out) and measures
/// both structures.
///
/// # Errors
/// When `layers` is outside `1..=MAX_LAYERS`, or the groom does not fit the mesh.
pub fn measure(
    mesh: pelt_core::Mesh,
    report: MeshReport,
    layers: u32,
    fin_faces: u32,
    groom: Option<Groom>,
) -> anyhow::Result<Stats> {
    if !(1..=MAX_LAYERS).contains(&layers) {
        anyhow::bail!("--layers {layers}: choose between 1 and {MAX_LAYERS}");
    }
    let params = FurParams { layers, length: FurLength::Constant(1.0), direction: GrowthDirection::default() };
    let fur = FurStructure::new_groomed(mesh, &params, groom)?;
    let unified = fur.footprint();
    // The footprint counts what was actually built.
    anyhow::ensure!(
        unified.vertices == fur.positions.len() as u64,
        "unified vertex count disagrees with the structure"
    );
    let separated_two_face_fins = SeparatedStructure { layers, fin_faces: 2 }.footprint_of(&fur);
    let separated_n_face_fins = SeparatedStructure { layers, fin_faces }.footprint_of(&fur);
    let vertices = |f: &Footprint| f.vertices;
    let bytes = |f: &Footprint| f.total_bytes();
    let savings = Savings {
        vertices_vs_two_face_fins_percent: unified.savings_percent(&separated_two_face_fins, vertices),
        vertices_vs_n_face_fins_percent: unified.savings_percent(&separated_n_face_fins, vertices),
        gpu_bytes_vs_two_face_fins_percent: unified.savings_percent(&separated_two_face_fins, bytes),
        gpu_bytes_vs_n_face_fins_percent: unified.savings_percent(&separated_n_face_fins, bytes),
    };
    Ok(Stats {
        mesh: report,
        layers,
        groom: None,
        fin_faces,
        unified,
        separated_two_face_fins,
        separated_n_face_fins,
        savings,
        motion: None,
    })
}

/// The human-readable report; on the built-in Box it adds the paper's printed numbers.
#[must_use]
pub fn table(stats: &Stats) -> String {
    let mut out = String::new();
    let r = &stats.mesh;
    let _ = writeln!(out, "{r}");
    if let Some(motion) = &stats.motion {
        motion_table(&mut out, motion);
    }
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "Table 2 on {} (V = {}, F = {}, E = {}; L = {} shells above the base)",
        r.source,
        thousands(r.vertices as u64),
        thousands(r.triangles as u64),
        thousands(r.edges as u64),
        stats.layers
    );
    if let Some(preset) = &stats.groom {
        let _ = writeln!(out, "groomed by {preset}: faces on bald triangles and edges are not drawn or counted");
    }
    let _ = writeln!(
        out,
        "{:<26} {:>10} {:>11} {:>11} {:>13} {:>13} {:>13}",
        "structure", "vertices", "shell faces", "fin faces", "vertex bytes", "index bytes", "GPU bytes"
    );
    let mut rows = vec![("unified (shared vertices)".to_owned(), &stats.unified)];
    rows.push(("separated, 2-face fins".to_owned(), &stats.separated_two_face_fins));
    if stats.fin_faces != 2 {
        rows.push((format!("separated, {}-face fins", stats.fin_faces), &stats.separated_n_face_fins));
    }
    for (name, f) in rows {
        let _ = writeln!(
            out,
            "{name:<26} {:>10} {:>11} {:>11} {:>13} {:>13} {:>13}",
            thousands(f.vertices),
            thousands(f.shell_faces),
            thousands(f.fin_faces),
            thousands(f.position_bytes + f.attribute_bytes),
            thousands(f.index_bytes),
            thousands(f.total_bytes())
        );
    }
    let s = &stats.savings;
    let _ = writeln!(
        out,
        "unified saves {:.2}% of the vertices and {:.2}% of the GPU bytes against 2-face fins",
        s.vertices_vs_two_face_fins_percent, s.gpu_bytes_vs_two_face_fins_percent
    );
    if stats.fin_faces != 2 {
        let _ = writeln!(
            out,
            "unified saves {:.2}% of the vertices and {:.2}% of the GPU bytes against {}-face fins",
            s.vertices_vs_n_face_fins_percent, s.gpu_bytes_vs_n_face_fins_percent, stats.fin_faces
        );
    }
    if r.source == format!("builtin:{}", Builtin::Box) && stats.layers == 16 {
        let (unified, two, thirty) = PAPER_BOX;
        let measured = (stats.unified.vertices, stats.separated_two_face_fins.vertices);
        let thirty_measured = (stats.fin_faces == 30).then_some(stats.separated_n_face_fins.vertices);
        let agrees = measured == (unified, two) && thirty_measured.is_none_or(|v| v == thirty);
        let _ = writeln!(
            out,
            "paper's Table 2, Box: {} / {} / {} vertices (unified / 2-face / 30-face): {}",
            thousands(unified),
            thousands(two),
            thousands(thirty),
            if agrees { "matches" } else { "DIFFERS" }
        );
    }
    out
}

/// Skins, joints and animations with their durations.
fn motion_table(out: &mut String, motion: &Motion) {
    let name = |n: &Option<String>| n.as_deref().map_or_else(|| "(unnamed)".to_owned(), |n| format!("{n:?}"));
    let joints: usize = motion.skins.iter().map(|s| s.joints).sum();
    let _ = writeln!(
        out,
        "  {} skins, {} joints, {} nodes, {} morph targets, {} animations",
        motion.skins.len(),
        joints,
        motion.nodes,
        motion.morph_targets,
        motion.animations.len()
    );
    for (k, skin) in motion.skins.iter().enumerate() {
        let _ = writeln!(out, "    skin {k} {}: {} joints", name(&skin.name), skin.joints);
    }
    for (k, animation) in motion.animations.iter().enumerate() {
        let _ = writeln!(
            out,
            "    animation {k} {}: {:.3} s, {} channels",
            name(&animation.name),
            animation.duration_secs,
            animation.channels
        );
    }
    for note in &motion.notes {
        let _ = writeln!(out, "    note: {note}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats_of(builtin: Builtin, layers: u32, fin_faces: u32) -> Stats {
        let (mesh, report) = builtin.mesh();
        measure(mesh, report, layers, fin_faces, None).unwrap()
    }

    #[test]
    fn the_paper_box_reproduces_table_2() {
        let stats = stats_of(Builtin::Box, 16, 30);
        assert_eq!(stats.unified.vertices, 5_032);
        assert_eq!(stats.separated_two_face_fins.vertices, 6_796);
        assert_eq!(stats.separated_n_face_fins.vertices, 31_492);
        let text = table(&stats);
        assert!(text.contains("5,032") && text.contains("6,796") && text.contains("31,492"), "{text}");
        assert!(text.contains("25.96%") && text.contains("84.02%"), "{text}");
        assert!(text.contains("matches"), "{text}");
        // The unified structure wins on GPU bytes too, not only on vertex counts.
        assert!(stats.savings.gpu_bytes_vs_two_face_fins_percent > 0.0);
        assert!(stats.savings.gpu_bytes_vs_n_face_fins_percent > stats.savings.gpu_bytes_vs_two_face_fins_percent);
    }

    #[test]
    fn two_face_fins_are_listed_once() {
        let text = table(&stats_of(Builtin::Torus, 8, 2));
        assert_eq!(text.matches("separated").count(), 1, "{text}");
        assert!(!text.contains("paper's"), "{text}");
    }

    #[test]
    fn json_carries_every_number() {
        let stats = stats_of(Builtin::Plane, 4, 30);
        let json: serde_json::Value = serde_json::to_value(&stats).unwrap();
        let v = stats.mesh.vertices as u64;
        let e = stats.mesh.edges as u64;
        assert_eq!(json["unified"]["vertices"], v * 5);
        assert_eq!(json["separated_n"]["vertices"], v * 5 + 30 * e);
        assert_eq!(json["separated2"]["vertices"], v * 5 + 2 * e);
        assert_eq!(json["mesh"]["boundary_loops"], 1);
        assert!(json["savings_vs_n_percent"].as_f64().unwrap() > 0.0);
        assert!(json["bytes_savings_vs_2_percent"].as_f64().unwrap() > 0.0);
    }

    #[test]
    fn bad_layer_counts_name_the_flag() {
        for layers in [0, MAX_LAYERS + 1] {
            let (mesh, report) = Builtin::Box.mesh();
            let message = format!("{:#}", measure(mesh, report, layers, 30, None).unwrap_err());
            assert!(message.contains("--layers"), "{message}");
        }
    }
}
