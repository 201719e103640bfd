//! The fur model's BSDF on the CPU: a line-for-line twin of `fur_bsdf` in
//! `shaders/fur_bsdf.wgsl`, for tests and offline references. Keep the two in step.

use glam::Vec3;

use crate::object::FurShading;

/// The wet parameters the BSDF reads (`FurLook::wet_shine`, `FurLook::wet_darkening`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WetLook {
    /// The highlight grows by `1 + shine * w`.
    pub shine: f32,
    /// The scattered lobes darken by `1 - darkening * w`.
    pub darkening: f32,
}

fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

fn hair_gaussian(width: f32, x: f32) -> f32 {
    (-0.5 * x * x / (width * width)).exp() / (2.506_628_3 * width)
}

fn hair_fresnel(cos_theta: f32) -> f32 {
    let f0 = 0.04652;
    let m = 1.0 - cos_theta;
    f0 + (1.0 - f0) * m.powi(5)
}

fn hair_r_albedo(cos_v: f32) -> f32 {
    let c = cos_v;
    0.173_927_42 * (hair_fresnel(c * 0.99759) + hair_fresnel(c * 0.36612))
        + 0.326_072_58 * (hair_fresnel(c * 0.94398) + hair_fresnel(c * 0.74237))
}

/// (white R lobe, albedo-tinted lobes) per unit irradiance from `l`, for unit strand tangent
/// `t`, toward-eye `v`, toward-light `l` and surface normal `n`, at wetness `wet`.
#[must_use]
pub fn mirror(t: Vec3, v: Vec3, l: Vec3, n: Vec3, wet: f32, shading: &FurShading, wet_look: WetLook) -> (f32, f32) {
    let sin_l = t.dot(l).clamp(-1.0, 1.0);
    let sin_v = t.dot(v).clamp(-1.0, 1.0);
    let lp = l - t * sin_l;
    let vp = v - t * sin_v;
    let cos_phi = lp.dot(vp) / (lp.length_squared() * vp.length_squared()).max(1e-8).sqrt();
    let cos_half_phi = (0.5 + 0.5 * cos_phi).clamp(0.0, 1.0).sqrt();
    let cos_l = (1.0 - sin_l * sin_l).max(0.0).sqrt();
    let cos_v = (1.0 - sin_v * sin_v).max(0.0).sqrt();
    let cos_theta_d = (0.5 + 0.5 * (cos_v * cos_l + sin_v * sin_l)).clamp(1e-4, 1.0).sqrt();
    let roughness = shading.roughness.clamp(0.05, 1.0) * (1.0 - 0.5 * wet);
    let b = roughness * roughness;
    let shift = shading.cuticle_tilt;
    let s = sin_l + sin_v;
    let n_dot_l = n.dot(l);
    let lit_side = smoothstep(-0.25, 0.6, n_dot_l);
    let through = smoothstep(-0.4, 0.05, n_dot_l);
    let r = hair_gaussian(b, s + 2.0 * shift)
        * 0.25
        * cos_half_phi
        * hair_fresnel((0.5 + 0.5 * v.dot(l)).clamp(0.0, 1.0).sqrt())
        * (1.0 + wet_look.shine * wet)
        * lit_side;
    let a = 1.0 / (1.19 / cos_theta_d + 0.36 * cos_theta_d);
    let h = cos_half_phi * (1.0 + a * (0.6 - 0.8 * cos_phi));
    let f_tt = hair_fresnel(cos_theta_d * (1.0 - h * h).clamp(0.0, 1.0).sqrt());
    let tt = hair_gaussian(0.5 * b, s - shift) * (-3.65 * cos_phi - 3.98).exp() * (1.0 - f_tt) * (1.0 - f_tt) * through;
    let f_trt = hair_fresnel(0.5 * cos_theta_d);
    let trt = hair_gaussian(2.0 * b, s - 4.0 * shift)
        * (17.0 * cos_phi - 16.78).exp()
        * (1.0 - f_trt)
        * (1.0 - f_trt)
        * f_trt
        * lit_side;
    let m = shading.medulla.clamp(0.0, 1.0);
    let scattered = hair_gaussian(b + 0.6, s) * (1.0 - 0.4 * cos_phi) * 0.159_154_94 * (1.0 - f_tt) * lit_side;
    let tinted =
        ((1.0 - m) * (tt + trt) + m * scattered) * (1.0 - hair_r_albedo(cos_v)) * (1.0 - wet_look.darkening * wet);
    (r, tinted)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions around the unit strand tangent `t` on an even grid in (sin theta, phi), each
    /// `4 pi / count` sr: the lobes are narrow in sin theta (Marschner's longitudinal Gaussians), so
    /// a grid along the strand integrates them far better than a lattice over the sphere.
    fn around(t: Vec3, rows: usize, columns: usize) -> Vec<Vec3> {
        let a = t.any_orthonormal_vector();
        let b = t.cross(a);
        let mut out = Vec::with_capacity(rows * columns);
        for i in 0..rows {
            let sin = -1.0 + 2.0 * (i as f32 + 0.5) / rows as f32;
            let cos = (1.0 - sin * sin).max(0.0).sqrt();
            for j in 0..columns {
                let phi = std::f32::consts::TAU * (j as f32 + 0.5) / columns as f32;
                out.push(t * sin + (a * phi.cos() + b * phi.sin()) * cos);
            }
        }
        out
    }

    const DRY: WetLook = WetLook { shine: 0.6, darkening: 0.5 };

    /// The white furnace: a white strand lit by radiance 1 from every direction (each light
    /// direction on the strand's own side of the surface, so no lobe is gated off) returns at
    /// most 1 toward every eye, for rough and smooth strands, with and without a medulla.
    #[test]
    fn a_white_strand_returns_at_most_the_light_it_gets() {
        let t = Vec3::new(0.2, -0.9, 0.3).normalize();
        let directions = around(t, 1500, 240);
        let weight = 4.0 * std::f32::consts::PI / directions.len() as f32;
        // Views from along the strand to across it, on both sides: the grazing ones are where
        // the R lobe's Fresnel grows.
        let views: Vec<Vec3> = (0..=40)
            .map(|k| {
                let sin = -0.98 + 1.96 * k as f32 / 40.0;
                t * sin + t.any_orthonormal_vector() * (1.0 - sin * sin).sqrt()
            })
            .collect();
        let mut most: f32 = 0.0;
        for shading in [
            FurShading { roughness: 0.35, medulla: 0.3, ..FurShading::default() },
            FurShading { roughness: 0.1, medulla: 0.0, ..FurShading::default() },
            FurShading { roughness: 0.8, medulla: 1.0, ..FurShading::default() },
            FurShading { roughness: 0.05, medulla: 0.0, cuticle_tilt: 10f32.to_radians(), ..FurShading::default() },
        ] {
            for v in &views {
                let returned: f32 = directions
                    .iter()
                    .map(|&l| {
                        let (r, tinted) = mirror(t, *v, l, l, 0.0, &shading, DRY);
                        (r + tinted) * weight
                    })
                    .sum();
                assert!(returned <= 1.0, "{shading:?} toward {v}: {returned}");
                most = most.max(returned);
            }
        }
        // And it is not dark: most of the light comes back somewhere.
        assert!(most > 0.3, "the strand returns at most {most}");
    }

    /// The transmitted lobe: light from behind a strand, seen across it, is brighter than the
    /// same light from the eye's side.
    #[test]
    fn back_light_passes_through() {
        let shading = FurShading { medulla: 0.0, ..FurShading::default() };
        let (t, v) = (Vec3::Y, Vec3::Z);
        let n = Vec3::X;
        let (r_back, back) = mirror(t, v, -v, n, 0.0, &shading, DRY);
        let (r_front, front) = mirror(t, v, v, n, 0.0, &shading, DRY);
        assert!(back > 4.0 * (front + r_front), "through {back}, reflected {front} + {r_front}");
        assert!(r_back >= 0.0);
    }
}
