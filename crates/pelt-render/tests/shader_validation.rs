//! Every WGSL module the renderer builds parses and validates with naga (no GPU needed).

fn validate(name: &str, source: &str) {
    let module =
        naga::front::wgsl::parse_str(source).unwrap_or_else(|error| panic!("{name}: {}", error.emit_to_string(source)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .unwrap_or_else(|error| panic!("{name}: {}", error.emit_to_string(source)));
}

#[test]
fn unified_module_validates() {
    validate("shading.wgsl + unified.wgsl", &pelt_render::unified_shader_source());
}

#[test]
fn separated_module_validates() {
    validate("shading.wgsl + separated.wgsl", &pelt_render::separated_shader_source());
}

#[test]
fn simulation_module_validates() {
    validate(
        "simulation_wind.wgsl + simulation.wgsl + simulation_inputs.wgsl + simulation_contact.wgsl + simulation_lone.wgsl",
        &pelt_render::simulation_shader_source(),
    );
    validate(
        "simulation_wind.wgsl + simulation.wgsl + simulation_inputs.wgsl + simulation_contact.wgsl + simulation_pooled.wgsl",
        &pelt_render::simulation_pooled_shader_source(),
    );
}

#[test]
fn silhouette_module_validates() {
    validate("shading.wgsl + unified.wgsl + silhouette.wgsl", &pelt_render::silhouette_shader_source());
}

#[test]
fn view_lod_module_validates() {
    validate("shading.wgsl + unified.wgsl + view_lod.wgsl", &pelt_render::view_lod_shader_source());
}

#[test]
fn pool_draw_module_validates() {
    validate("shading.wgsl over a pool + unified.wgsl + pool_draws.wgsl", &pelt_render::pool_draw_shader_source());
}

#[test]
fn prepass_module_validates() {
    validate("shading.wgsl + unified.wgsl + prepass.wgsl", &pelt_render::prepass_shader_source());
}

#[test]
fn strands_module_validates() {
    validate("shading.wgsl + strands.wgsl", &pelt_render::strands_shader_source());
}

#[test]
fn every_wgsl_file_is_part_of_a_validated_module() {
    let sources = [
        pelt_render::unified_shader_source(),
        pelt_render::separated_shader_source(),
        pelt_render::simulation_shader_source(),
        pelt_render::simulation_pooled_shader_source(),
        pelt_render::silhouette_shader_source(),
        pelt_render::view_lod_shader_source(),
        pelt_render::pool_draw_shader_source(),
        pelt_render::prepass_shader_source(),
        pelt_render::strands_shader_source(),
        pelt_render::skinning_shader_source(),
        pelt_render::herd_posing_shader_source(),
        pelt_render::shadow_copy_shader_source(),
    ];
    // Every .wgsl under src/, wherever it lies.
    let mut dirs = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src")];
    let mut checked = 0;
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("src dir") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let text = std::fs::read_to_string(&path).expect("read");
                assert!(sources.iter().any(|s| s.contains(&text)), "{} is in no validated module", path.display());
                checked += 1;
            }
        }
    }
    assert_eq!(
        checked, 22,
        "shading, object_pool, pool_draws, wet, fur_bsdf, shadows, unified, prepass, separated, scan, silhouette, view_lod, \
         simulation_wind, simulation, simulation_inputs, simulation_contact, simulation_lone, simulation_pooled, strands, skinning, herd_posing and shadow_copy"
    );
}

#[test]
fn shadow_copy_module_validates() {
    validate("shadow_copy.wgsl", &pelt_render::shadow_copy_shader_source());
}

#[test]
fn skinning_module_validates() {
    validate("skinning.wgsl", &pelt_render::skinning_shader_source());
}
