//! Spherical harmonics of order 2 (9 coefficients per channel): the environment's radiance as
//! projected, its irradiance by the cosine lobe's convolution (Ramamoorthi and Hanrahan 2001),
//! and a blurred radiance for rough highlights.

use std::f32::consts::PI;

use glam::Vec3;

/// Bands kept (l = 0, 1, 2).
pub const SH_BANDS: usize = 3;

/// The 9 real SH basis functions at unit direction `d`, in the order (l, m) = (0,0), (1,-1),
/// (1,0), (1,1), (2,-2), (2,-1), (2,0), (2,1), (2,2) with y, z, x for band 1.
#[must_use]
pub fn sh9_basis(d: Vec3) -> [f32; 9] {
    let Vec3 { x, y, z } = d;
    [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_4 * x * y,
        1.092_548_4 * y * z,
        0.315_391_57 * (3.0 * z * z - 1.0),
        1.092_548_4 * x * z,
        0.546_274_2 * (x * x - y * y),
    ]
}

/// The band of coefficient `k`.
const BAND: [usize; 9] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

/// Radiance over the sphere as 9 RGB coefficients.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sh9 {
    /// Linear RGB per basis function, in [`sh9_basis`]'s order.
    pub coefficients: [Vec3; 9],
}

impl Sh9 {
    /// A uniform radiance.
    #[must_use]
    pub fn uniform(radiance: Vec3) -> Self {
        let mut coefficients = [Vec3::ZERO; 9];
        coefficients[0] = radiance * (4.0 * PI * 0.282_094_8);
        Self { coefficients }
    }

    /// The radiance the coefficients hold toward `d` (band-limited).
    #[must_use]
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.weighted(d, [1.0; SH_BANDS])
    }

    /// The irradiance on a surface of unit normal `n`: the radiance convolved with the clamped
    /// cosine (band weights pi, 2pi/3, pi/4).
    #[must_use]
    pub fn irradiance(&self, n: Vec3) -> Vec3 {
        self.weighted(n, [PI, 2.0 * PI / 3.0, PI / 4.0])
    }

    /// The radiance blurred by a lobe of angular width `width` radians (each band damped by
    /// `exp(-l(l+1) width^2 / 2)`, the heat kernel): the cheap filtered lookup of rough
    /// highlights.
    #[must_use]
    pub fn blurred(&self, d: Vec3, width: f32) -> Vec3 {
        self.weighted(d, band_damping(width))
    }

    /// The mean radiance over the sphere.
    #[must_use]
    pub fn mean(&self) -> Vec3 {
        self.coefficients[0] * 0.282_094_8
    }

    fn weighted(&self, d: Vec3, band: [f32; SH_BANDS]) -> Vec3 {
        let basis = sh9_basis(d);
        (0..9).fold(Vec3::ZERO, |sum, k| sum + self.coefficients[k] * (basis[k] * band[BAND[k]]))
    }

    /// Every coefficient times `scale`.
    #[must_use]
    pub fn scaled(&self, scale: f32) -> Self {
        Self { coefficients: self.coefficients.map(|c| c * scale) }
    }
}

/// The heat kernel's damping of bands 0, 1 and 2 for a lobe of width `width` radians.
#[must_use]
pub fn band_damping(width: f32) -> [f32; SH_BANDS] {
    let w2 = width * width;
    [1.0, (-w2).exp(), (-3.0 * w2).exp()]
}
