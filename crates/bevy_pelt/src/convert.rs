//! Bevy 0.20 uses glam 0.33 and Pelt glam 0.34: the same layouts, different types.

/// A Bevy vector as Pelt's.
pub(crate) fn to_pelt(v: bevy::math::Vec3) -> glam::Vec3 {
    glam::Vec3::from_array(v.to_array())
}

/// A Bevy affine transform as Pelt's.
pub(crate) fn to_pelt_affine(a: &bevy::math::Affine3A) -> glam::Affine3A {
    glam::Affine3A::from_cols_array(&a.to_cols_array())
}

/// A Bevy matrix as Pelt's.
pub(crate) fn to_pelt_mat4(m: &bevy::math::Mat4) -> glam::Mat4 {
    glam::Mat4::from_cols_array(&m.to_cols_array())
}
