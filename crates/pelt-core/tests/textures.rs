//! Shell and fin texture generation: determinism, coverage, styles, patterns and colours.

use pelt_core::texture::{
    self, ColourMode, ColourParams, FurTextures, ImageRgba8, Rgb, Style, TextureInputs, TextureParams,
};

const SIZE: u32 = 64;
const LAYERS: u32 = 8;

fn small(seed: u64) -> TextureParams {
    TextureParams { size: SIZE, seed, ..TextureParams::default() }
}

fn make(params: &TextureParams) -> FurTextures {
    texture::generate(LAYERS, params, &ColourParams::default(), &TextureInputs::default()).unwrap()
}

fn alphas(textures: &FurTextures, k: u32) -> Vec<f32> {
    textures.slice(k).chunks_exact(4).map(|p| f32::from(p[3]) / 255.0).collect()
}

#[test]
fn layout_and_sizes() {
    let textures = make(&small(1));
    assert_eq!(textures.shell.len(), (SIZE * SIZE * 4 * LAYERS) as usize);
    assert_eq!((textures.fin_width, textures.fin_height), (SIZE, 32));
    assert_eq!(textures.fin.len(), (SIZE * 32 * 4) as usize);
    assert!(textures.surface.is_none());
    assert_eq!(textures.mip_levels(), 7);
    let mips = textures.shell_mips();
    assert_eq!(mips.len(), 6);
    assert_eq!(mips[0].len(), (32 * 32 * 4 * LAYERS) as usize);
    assert_eq!(mips[5].len(), (4 * LAYERS) as usize);
    let fin_mips = textures.fin_mips();
    assert_eq!(fin_mips.len(), 6);
    assert_eq!(fin_mips[0].len(), (32 * 16 * 4) as usize);
    assert_eq!(fin_mips[5].len(), 4);
    // Alpha-weighted filtering keeps the mean coverage of the slice.
    let mean_alpha =
        |bytes: &[u8]| bytes.chunks_exact(4).map(|p| f64::from(p[3])).sum::<f64>() / (bytes.len() / 4) as f64 / 255.0;
    let level0 = mean_alpha(textures.slice(0));
    let level6 = mean_alpha(&mips[5][0..4]);
    assert!((level0 - level6).abs() < 0.01, "{level0} vs {level6}");
}

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let a = make(&small(7));
    assert_eq!(a, make(&small(7)));
    let b = make(&small(8));
    assert_ne!(a.shell, b.shell);
    assert_ne!(a.fin, b.fin);
}

#[test]
fn thread_count_does_not_change_the_bytes() {
    let params = TextureParams { curl_radius: 2.0, curl_turns: 1.5, clump: 0.5, ..small(3) };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| make(&params))
    };
    let one = run(1);
    assert_eq!(one, run(4));
    assert_eq!(one, run(3));
}

#[test]
fn coverage_falls_from_root_to_tip() {
    let textures = make(&small(5));
    let coverage: Vec<f32> = (0..LAYERS).map(|k| textures.coverage(k)).collect();
    assert!(coverage.windows(2).all(|w| w[1] <= w[0] + 1e-3), "{coverage:?}");
    assert!(coverage[0] > 0.3, "{coverage:?}");
    assert!(coverage[LAYERS as usize - 1] < coverage[0] * 0.35, "{coverage:?}");
    // The fin thins toward the tips too: row 0 is the tip, the last row the root.
    let row_alpha = |row: u32| {
        let bytes = &textures.fin[(row * textures.fin_width * 4) as usize..][..(textures.fin_width * 4) as usize];
        bytes.chunks_exact(4).map(|p| u32::from(p[3])).sum::<u32>()
    };
    assert!(row_alpha(0) < row_alpha(textures.fin_height - 1));
}

#[test]
fn root_coverage_grows_with_density() {
    let coverage: Vec<f32> =
        [0.1, 0.4, 0.9].iter().map(|&density| make(&TextureParams { density, ..small(2) }).coverage(0)).collect();
    assert!(coverage[0] < coverage[1] && coverage[1] < coverage[2], "{coverage:?}");
    assert_eq!(make(&TextureParams { density: 0.0, ..small(2) }).coverage(0), 0.0);
}

#[test]
fn coverage_follows_density_not_tile_size() {
    // Same density, four times the texels: about four times the strands, each the same size in
    // texels, so the same coverage but finer strands relative to the tile.
    let strands = |size| {
        let textures = make(&TextureParams { size, density: 0.2, root_blur: 0.0, ..small(4) });
        (textures.coverage(0), textures.size)
    };
    let (small_coverage, _) = strands(64);
    let (large_coverage, _) = strands(128);
    assert!((small_coverage - large_coverage).abs() < 0.05, "{small_coverage} vs {large_coverage}");
}

/// Share of the alpha in slice `k` that lies over texels covered in the root slice.
fn overlap_with_root(textures: &FurTextures, k: u32) -> f32 {
    let root = alphas(textures, 0);
    let upper = alphas(textures, k);
    let on_root: f32 = root.iter().zip(&upper).map(|(r, u)| if *r > 0.5 { *u } else { 0.0 }).sum();
    on_root / upper.iter().sum::<f32>()
}

#[test]
fn straight_strands_keep_their_place_random_ones_move() {
    let sparse = TextureParams {
        density: 0.1,
        length_variation: 0.0,
        lean: 8.0,
        clump: 0.0,
        root_blur: 0.0,
        taper: 0.3,
        ..small(9)
    };
    let straight = make(&TextureParams { style: Style::Straight, ..sparse.clone() });
    let random = make(&TextureParams { style: Style::Random, ..sparse.clone() });
    let mixed = make(&TextureParams { style: Style::Mixed, mixed_ratio: 0.5, ..sparse });
    let top = LAYERS - 1;
    let (s, r, m) =
        (overlap_with_root(&straight, top), overlap_with_root(&random, top), overlap_with_root(&mixed, top));
    assert!(s > 0.95, "straight {s}");
    assert!(r < 0.4, "random {r}");
    assert!(r < m && m < s, "mixed {m} between random {r} and straight {s}");
}

#[test]
fn curl_and_clumping_move_strands_off_their_roots() {
    let base = TextureParams { style: Style::Straight, density: 0.1, length_variation: 0.0, clump: 0.0, ..small(6) };
    let top = LAYERS - 1;
    let curled = make(&TextureParams { curl_radius: 3.0, curl_turns: 0.75, ..base.clone() });
    let clumped = make(&TextureParams { clump: 1.0, clump_size: 16.0, ..base.clone() });
    assert!(overlap_with_root(&make(&base), top) > 0.95);
    assert!(overlap_with_root(&curled, top) < 0.6);
    assert!(overlap_with_root(&clumped, top) < 0.6);
}

#[test]
fn tiles_wrap_seamlessly() {
    // Strands near the right edge must spill onto the left: no texel column stays empty at the
    // seam more often than in the middle of a dense tile.
    let textures = make(&TextureParams { density: 0.9, ..small(11) });
    let root = alphas(&textures, 0);
    let column = |x: usize| (0..SIZE as usize).map(|y| root[y * SIZE as usize + x]).sum::<f32>() / SIZE as f32;
    let middle = (28..36).map(column).sum::<f32>() / 8.0;
    for x in [0, SIZE as usize - 1] {
        assert!((column(x) - middle).abs() < 0.2 * middle, "column {x}: {} vs {middle}", column(x));
    }
}

#[test]
fn a_black_pattern_grows_nothing_and_a_pattern_tints() {
    let black = ImageRgba8::filled(16, 16, [0, 0, 0, 255]);
    let inputs = TextureInputs { pattern: Some(black), ..TextureInputs::default() };
    let textures = texture::generate(LAYERS, &small(1), &ColourParams::default(), &inputs).unwrap();
    assert!(textures.shell.chunks_exact(4).all(|p| p[3] == 0));
    assert!(textures.fin.chunks_exact(4).all(|p| p[3] == 0));

    // Left half black, right half pure blue: strands only on the right, all of them blue.
    let mut half = ImageRgba8::filled(16, 16, [0, 0, 255, 255]);
    for y in 0..16 {
        for x in 0..6 {
            half.pixels[(y * 16 + x) * 4 + 2] = 0;
        }
    }
    let white = ColourParams { colour: Rgb([255, 255, 255]), ..ColourParams::default() };
    let inputs = TextureInputs { pattern: Some(half), ..TextureInputs::default() };
    let params = TextureParams { style: Style::Straight, clump: 0.0, ..small(1) };
    let textures = texture::generate(LAYERS, &params, &white, &inputs).unwrap();
    let root = textures.slice(0);
    let covered_at = |x: usize| (0..SIZE as usize).filter(|y| root[(y * SIZE as usize + x) * 4 + 3] > 128).count();
    assert_eq!((8..16).map(covered_at).sum::<usize>(), 0, "the black side stays bare");
    assert!((40..56).map(covered_at).sum::<usize>() > 100, "the blue side grows fur");
    assert!(root.chunks_exact(4).filter(|p| p[3] > 0).all(|p| p[0] == 0 && p[1] == 0 && p[2] > 0));
}

#[test]
fn height_colours_vary_from_root_to_tip() {
    let colour = ColourParams {
        mode: ColourMode::Height,
        height_colours: vec![Rgb([255, 0, 0]), Rgb([0, 0, 255])],
        brightness_variation: 0.0,
        ..ColourParams::default()
    };
    let textures = texture::generate(LAYERS, &small(1), &colour, &TextureInputs::default()).unwrap();
    let mean_colour = |k: u32| {
        let covered: Vec<&[u8]> = textures.slice(k).chunks_exact(4).filter(|p| p[3] > 200).collect();
        let mean = |c: usize| covered.iter().map(|p| f32::from(p[c])).sum::<f32>() / covered.len() as f32;
        (mean(0), mean(2))
    };
    let (root_red, root_blue) = mean_colour(0);
    let (tip_red, tip_blue) = mean_colour(LAYERS - 2);
    assert!(root_red > 200.0 && root_blue < 60.0, "root ({root_red}, {root_blue})");
    assert!(tip_red < 80.0 && tip_blue > 170.0, "tip ({tip_red}, {tip_blue})");
}

#[test]
fn single_colour_varies_in_brightness_and_surface_mode_is_grey() {
    let colour = ColourParams { colour: Rgb([200, 100, 50]), brightness_variation: 0.5, ..ColourParams::default() };
    let textures = texture::generate(LAYERS, &small(1), &colour, &TextureInputs::default()).unwrap();
    let reds: Vec<u8> = textures.slice(0).chunks_exact(4).filter(|p| p[3] == 255).map(|p| p[0]).collect();
    let (low, high) = (reds.iter().min().unwrap(), reds.iter().max().unwrap());
    assert!(*high <= 200 && *low < 140, "red from {low} to {high}");

    let surface = ImageRgba8::filled(8, 4, [10, 20, 30, 255]);
    let colour = ColourParams { mode: ColourMode::Surface, surface: Some("s.png".into()), ..ColourParams::default() };
    let inputs = TextureInputs { surface: Some(surface.clone()), ..TextureInputs::default() };
    let textures = texture::generate(LAYERS, &small(1), &colour, &inputs).unwrap();
    assert_eq!(textures.surface, Some(surface));
    assert!(textures.slice(0).chunks_exact(4).all(|p| p[0] == p[1] && p[1] == p[2]));
    // Surface mode without its image is an error, not a panic.
    let error = texture::generate(LAYERS, &small(1), &colour, &TextureInputs::default()).unwrap_err();
    assert!(error.to_string().contains("colour.surface"), "{error}");
}

#[test]
fn bad_parameters_name_their_key() {
    let cases = [
        (TextureParams { size: 48, ..small(1) }, "texture.size"),
        (TextureParams { size: 16, ..small(1) }, "texture.size"),
        (TextureParams { density: 1.5, ..small(1) }, "texture.density"),
        (TextureParams { thickness: f32::NAN, ..small(1) }, "texture.thickness"),
        (TextureParams { clump_size: 500.0, ..small(1) }, "texture.clump_size"),
    ];
    for (params, key) in cases {
        let error = texture::generate(LAYERS, &params, &ColourParams::default(), &TextureInputs::default());
        assert!(error.unwrap_err().to_string().starts_with(key), "{key}");
    }
    let error = texture::generate(0, &small(1), &ColourParams::default(), &TextureInputs::default()).unwrap_err();
    assert!(error.to_string().contains("layers"));
}

#[test]
fn shipped_leopard_pattern_is_the_generated_one() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/patterns/leopard.png");
    let expected = texture::leopard_pattern(256, 7);
    if std::env::var_os("PELT_WRITE_PATTERNS").is_some() {
        expected.save_png(&path).unwrap();
    }
    let shipped = ImageRgba8::load(&path).unwrap();
    assert!(shipped == expected, "assets/patterns/leopard.png is stale: rerun with PELT_WRITE_PATTERNS=1");
}

/// The strands' lean the wet partings read: none for straight strands without clumping pull,
/// every strand leaning `lean * (0.5..1)` texels for the random style (mean 0.75 `lean`), the
/// mixed style's share of them, and the same numbers on every run.
#[test]
fn strand_lean_is_the_share_that_leans_and_its_mean_offset() {
    let unpulled = |style, lean| TextureParams { style, lean, clump: 0.0, size: 256, ..TextureParams::default() };
    let straight = make(&unpulled(Style::Straight, 5.0)).lean;
    assert_eq!((straight.share, straight.texels), (0.0, 0.0));
    let random = make(&unpulled(Style::Random, 6.0)).lean;
    assert!(random.share > 0.999, "{random:?}");
    assert!((random.texels - 4.5).abs() < 0.1, "{random:?}");
    let mixed = make(&TextureParams { mixed_ratio: 0.6, ..unpulled(Style::Mixed, 6.0) }).lean;
    assert!((mixed.share - 0.6).abs() < 0.03, "{mixed:?}");
    assert!((mixed.texels - 4.5).abs() < 0.15, "{mixed:?}");
    assert_eq!(make(&unpulled(Style::Mixed, 6.0)).lean, mixed);
}

#[test]
fn a_texel_holds_its_strands_tilt_times_its_coverage() {
    let tilt_at = |textures: &FurTextures, k: u32, texel: usize| {
        let i = (k as usize * (SIZE * SIZE) as usize + texel) * 2;
        let byte = |b: u8| f32::from(b as i8) * texture::TILT_STEP_TEXELS;
        glam::Vec2::new(byte(textures.strand_tilt[i]), byte(textures.strand_tilt[i + 1]))
    };
    // Straight strands stand on their roots: no tilt anywhere.
    let straight = make(&TextureParams { style: Style::Straight, clump: 0.0, ..small(3) });
    assert_eq!(straight.strand_tilt.len(), (SIZE * SIZE * LAYERS * 2) as usize);
    assert!(straight.strand_tilt.iter().all(|&b| b == 0));

    // Leaning, pulled and curled strands: where one strand alone covers a texel wholly, the texel
    // holds how fast that strand's cross-section travels there, measured here by differencing
    // its centre across the slice's height.
    let params = TextureParams {
        style: Style::Random,
        lean: 6.0,
        clump: 0.4,
        curl_radius: 1.5,
        curl_turns: 1.0,
        density: 0.3,
        ..small(5)
    };
    let field = texture::StrandField::new(&params, &ColourParams::default(), &TextureInputs::default()).unwrap();
    let textures = texture::generate_from(LAYERS, &field);
    let (mut checked, mut moving) = (0, 0);
    for k in [1, LAYERS / 2, LAYERS - 2] {
        let t = (k + 1) as f32 / LAYERS as f32;
        let alpha = alphas(&textures, k);
        let near: Vec<_> = field.strands.iter().filter(|s| s.length_factor() >= t + 0.05).collect();
        for (texel, &a) in alpha.iter().enumerate() {
            let p = glam::Vec2::new((texel as u32 % SIZE) as f32 + 0.5, (texel as u32 / SIZE) as f32 + 0.5);
            // Distances on the wrapping tile, to every strand's cross-section that could reach.
            let reach = |s: &&&texture::Strand| {
                let d = s.centre(t) - p;
                let wrapped = d - (d / SIZE as f32).round() * SIZE as f32;
                wrapped.length() < s.radius_at(t, params.taper) + 1.0
            };
            let covering: Vec<_> = near.iter().filter(reach).collect();
            let all_alive = field.strands.iter().filter(|s| s.length_factor() >= t).count() == near.len();
            if a < 0.999 || covering.len() != 1 || !all_alive {
                continue;
            }
            let h = 1e-3;
            let expected = (covering[0].centre(t + h) - covering[0].centre(t - h)) / (2.0 * h);
            let stored = tilt_at(&textures, k, texel);
            assert!(
                (stored - expected).abs().max_element() <= texture::TILT_STEP_TEXELS,
                "slice {k} texel {texel}: {stored} against {expected}"
            );
            checked += 1;
            moving += usize::from(expected.length() > 1.0);
        }
    }
    assert!(checked > 50 && moving > 25, "{checked} texels checked, {moving} of them tilted");
}
