//! A prim's `xformOp`s as one matrix.

use glam::{Mat4, Quat, Vec3};

use super::read::PrimInfo;

/// A prim's own transform from its `xformOpOrder`, and whether it resets its parents'.
pub(super) fn local_transform(info: &PrimInfo) -> Result<(Mat4, bool), String> {
    let mut matrix = Mat4::IDENTITY;
    let mut reset = false;
    for entry in &info.order {
        if entry == "!resetXformStack!" {
            reset = true;
            matrix = Mat4::IDENTITY;
            continue;
        }
        let (invert, name) = match entry.strip_prefix("!invert!") {
            Some(name) => (true, name),
            None => (false, entry.as_str()),
        };
        let Some((_, value)) = info.ops.iter().find(|(n, _)| n == name) else {
            return Err(format!("xformOpOrder names {name}, which the prim does not have"));
        };
        let numbers = value.numbers().ok_or_else(|| format!("{name} is not a number or tuple"))?;
        let op = name.trim_start_matches("xformOp:");
        let kind = op.split(':').next().unwrap_or(op);
        let v = |k: usize| numbers.get(k).copied().unwrap_or(0.0) as f32;
        let vec3 = || Vec3::new(v(0), v(1), v(2));
        let wanted = |n: usize| {
            if numbers.len() == n { Ok(()) } else { Err(format!("{name} has {} numbers, expected {n}", numbers.len())) }
        };
        let op_matrix = match kind {
            "translate" => {
                wanted(3)?;
                Mat4::from_translation(vec3())
            }
            "scale" => {
                wanted(3)?;
                Mat4::from_scale(vec3())
            }
            "rotateX" | "rotateY" | "rotateZ" => {
                wanted(1)?;
                let angle = v(0).to_radians();
                match kind {
                    "rotateX" => Mat4::from_rotation_x(angle),
                    "rotateY" => Mat4::from_rotation_y(angle),
                    _ => Mat4::from_rotation_z(angle),
                }
            }
            "orient" => {
                wanted(4)?;
                // USDA writes the real part first.
                Mat4::from_quat(Quat::from_xyzw(v(1), v(2), v(3), v(0)).normalize())
            }
            "transform" => {
                wanted(16)?;
                // USD's rows (row vectors, translation last) are glam's columns.
                let flat: Vec<f32> = numbers.iter().map(|&x| x as f32).collect();
                Mat4::from_cols_slice(&flat)
            }
            rotate if rotate.len() == 9 && rotate.starts_with("rotate") => {
                wanted(3)?;
                // rotateXYZ turns about X first: the matrix is Z * Y * X.
                let mut rotation = Mat4::IDENTITY;
                for axis in rotate[6..].chars() {
                    let (k, turn): (usize, fn(f32) -> Mat4) = match axis {
                        'X' => (0, Mat4::from_rotation_x),
                        'Y' => (1, Mat4::from_rotation_y),
                        'Z' => (2, Mat4::from_rotation_z),
                        _ => return Err(format!("{name}: unknown rotation order")),
                    };
                    rotation = turn(v(k).to_radians()) * rotation;
                }
                rotation
            }
            _ => return Err(format!("{name}: an xformOp Pelt does not read")),
        };
        let op_matrix = if invert { op_matrix.inverse() } else { op_matrix };
        matrix *= op_matrix;
    }
    if !matrix.is_finite() {
        return Err("the prim's transform is not finite".to_owned());
    }
    Ok((matrix, reset))
}
