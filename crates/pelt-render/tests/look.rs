//! Renders the scenes the goldens use into the target folder, for eyeballing while tuning.
//! `cargo test -p pelt-render --test look -- --nocapture` prints where.

mod common;

use common::*;
use pelt_core::Builtin;

#[test]
fn bunny_renders_fur_over_the_silhouette() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let textures = strand_textures(128, 16, BROWN_ROOT, BROWN_TIP);
    let headless = headless(512, 512);
    let renderer = headless.renderer(&fur, &textures).expect("renderer");
    let start = std::time::Instant::now();
    let image = headless.render(&renderer, &framed(&fur, 1.0), &settings()).expect("frame");
    println!("first frame {:?}", start.elapsed());
    let start = std::time::Instant::now();
    let _ = headless.render(&renderer, &framed(&fur, 1.0), &settings()).expect("frame");
    println!("second frame {:?}", start.elapsed());
    for (name, s) in [
        ("no fins", pelt_render::RenderSettings { fins: false, ..settings() }),
        ("no shells", pelt_render::RenderSettings { shells: false, ..settings() }),
        ("skin only", pelt_render::RenderSettings { shells: false, fins: false, ..settings() }),
    ] {
        let start = std::time::Instant::now();
        let _ = headless.render(&renderer, &framed(&fur, 1.0), &s).expect("frame");
        println!("{name} {:?}", start.elapsed());
    }
    let path = out_dir().join("look-bunny.png");
    image.save(&path).expect("save");
    println!("{}", path.display());
    let (centre, radius) = fur.mesh.bounding_sphere();
    let close = pelt_render::Camera::orbit(centre + glam::Vec3::new(0.0, radius * 0.5, 0.0), 30.0, 15.0, radius * 1.2);
    let image = headless.render(&renderer, &close, &settings()).expect("frame");
    image.save(out_dir().join("look-bunny-close.png")).expect("save");
    assert!(image.pixels().filter(|p| covered(p, [15, 16, 17])).count() > 1000);
}
