//! `W` floats processed as one: the value type of the batched kernels ([`super::kernel`]).
//!
//! Every operation is a fixed-length loop marked `#[inline(always)]`, so it is compiled with the
//! target features of the function it lands in: 256-bit AVX2 and FMA instructions inside the
//! kernel's `#[target_feature]` copy, SSE and a libm `fmaf` call elsewhere. Both copies perform
//! the same IEEE operations in the same order (exact division and square root, fused
//! multiply-adds written out with [`F::mul_add`], selects instead of branches), so they give the
//! same bytes. Nothing here is approximate (no `rcp`/`rsqrt`): that is what keeps the paths equal.

// Index loops over fixed lane counts are the form LLVM turns into one vector instruction.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Div, Mul, Neg, Sub};

/// `W` lanes of `f32`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct F<const W: usize>(pub [f32; W]);

/// A lane mask: all bits set where true. Selects are bitwise, never branches.
#[derive(Clone, Copy, Debug)]
pub(crate) struct M<const W: usize>([u32; W]);

macro_rules! binary {
    ($trait:ident, $method:ident, $op:tt) => {
        impl<const W: usize> $trait for F<W> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                let mut out = [0.0; W];
                for i in 0..W {
                    out[i] = self.0[i] $op other.0[i];
                }
                Self(out)
            }
        }
    };
}

binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl<const W: usize> Neg for F<W> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        let mut out = [0.0; W];
        for i in 0..W {
            out[i] = -self.0[i];
        }
        Self(out)
    }
}

macro_rules! compare {
    ($name:ident, $op:tt) => {
        #[inline(always)]
        pub fn $name(self, other: Self) -> M<W> {
            let mut out = [0; W];
            for i in 0..W {
                out[i] = if self.0[i] $op other.0[i] { u32::MAX } else { 0 };
            }
            M(out)
        }
    };
}

impl<const W: usize> F<W> {
    #[inline(always)]
    pub fn splat(value: f32) -> Self {
        Self([value; W])
    }

    /// `self * a + b`, rounded once.
    #[inline(always)]
    pub fn mul_add(self, a: Self, b: Self) -> Self {
        let mut out = [0.0; W];
        for i in 0..W {
            out[i] = self.0[i].mul_add(a.0[i], b.0[i]);
        }
        Self(out)
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        let mut out = [0.0; W];
        for i in 0..W {
            out[i] = self.0[i].sqrt();
        }
        Self(out)
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        let mut out = [0.0; W];
        for i in 0..W {
            out[i] = f32::from_bits(self.0[i].to_bits() & 0x7FFF_FFFF);
        }
        Self(out)
    }

    /// The smaller of the two; `other` where `self` is NaN (like `minps` with `other` second).
    #[inline(always)]
    pub fn min(self, other: Self) -> Self {
        self.lt(other).select(self, other)
    }

    /// The larger of the two; `other` where `self` is NaN.
    #[inline(always)]
    pub fn max(self, other: Self) -> Self {
        self.gt(other).select(self, other)
    }

    compare!(lt, <);
    compare!(gt, >);
}

impl<const W: usize> M<W> {
    /// `a` where the mask is set, else `b`.
    #[inline(always)]
    pub fn select(self, a: F<W>, b: F<W>) -> F<W> {
        let mut out = [0.0; W];
        for i in 0..W {
            out[i] = f32::from_bits((a.0[i].to_bits() & self.0[i]) | (b.0[i].to_bits() & !self.0[i]));
        }
        F(out)
    }

    #[inline(always)]
    pub fn and(self, other: Self) -> Self {
        let mut out = [0; W];
        for i in 0..W {
            out[i] = self.0[i] & other.0[i];
        }
        Self(out)
    }
}

/// Three lane vectors: `x`, `y`, `z` of `W` strands.
#[derive(Clone, Copy, Debug)]
pub(crate) struct V3<const W: usize> {
    pub x: F<W>,
    pub y: F<W>,
    pub z: F<W>,
}

impl<const W: usize> V3<W> {
    #[inline(always)]
    pub fn splat(x: f32, y: f32, z: f32) -> Self {
        Self { x: F::splat(x), y: F::splat(y), z: F::splat(z) }
    }

    /// `a . b` as `x*x + (y*y + (z*z))`, fused.
    #[inline(always)]
    pub fn dot(self, other: Self) -> F<W> {
        self.x.mul_add(other.x, self.y.mul_add(other.y, self.z * other.z))
    }

    /// `a x b`, each component one product and one fused multiply-subtract.
    #[inline(always)]
    pub fn cross(self, other: Self) -> Self {
        Self {
            x: self.y.mul_add(other.z, -(self.z * other.y)),
            y: self.z.mul_add(other.x, -(self.x * other.z)),
            z: self.x.mul_add(other.y, -(self.y * other.x)),
        }
    }

    #[inline(always)]
    pub fn scale(self, s: F<W>) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s }
    }

    /// `self * s + add`, fused per component.
    #[inline(always)]
    pub fn mul_add(self, s: F<W>, add: Self) -> Self {
        Self { x: self.x.mul_add(s, add.x), y: self.y.mul_add(s, add.y), z: self.z.mul_add(s, add.z) }
    }

    #[inline(always)]
    pub fn select(mask: M<W>, a: Self, b: Self) -> Self {
        Self { x: mask.select(a.x, b.x), y: mask.select(a.y, b.y), z: mask.select(a.z, b.z) }
    }
}
