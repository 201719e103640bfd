//! Shell and fin texture generation at the paper's tile sizes.

use criterion::{Criterion, criterion_group, criterion_main};
use pelt_core::texture::{self, ColourParams, TextureInputs, TextureParams};

fn generation(c: &mut Criterion) {
    let mut group = c.benchmark_group("textures");
    group.sample_size(10);
    for (size, layers) in [(512, 16), (1024, 32)] {
        let params = TextureParams { size, ..TextureParams::default() };
        let colour = ColourParams::default();
        let inputs = TextureInputs::default();
        group.bench_function(format!("generate_{size}x{size}x{layers}"), |b| {
            b.iter(|| texture::generate(layers, &params, &colour, &inputs).expect("valid parameters"));
        });
    }
    group.finish();
}

criterion_group!(benches, generation);
criterion_main!(benches);
