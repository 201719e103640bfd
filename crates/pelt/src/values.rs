//! Values the commands' arguments share: image and window sizes, vectors, MSAA sample counts.

use glam::Vec3;

/// The largest side of an image or window: what every GPU Pelt runs on can hold as a texture.
pub const MAX_SIDE_PX: u32 = 16_384;

pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let parsed = text.split_once(['x', 'X']).and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
    match parsed {
        Some((w, h)) if (1..=MAX_SIDE_PX).contains(&w) && (1..=MAX_SIDE_PX).contains(&h) => Ok((w, h)),
        _ => Err(format!("expected WIDTHxHEIGHT with each side from 1 to {MAX_SIDE_PX}, e.g. 1280x720, got {text:?}")),
    }
}

pub fn parse_msaa(text: &str) -> Result<u32, String> {
    match text.trim().parse() {
        Ok(samples @ (1 | 2 | 4 | 8)) => Ok(samples),
        _ => Err(format!("expected 1, 2, 4 or 8 samples, got {text:?}")),
    }
}

/// A wetness, `0..=1` (0 dry, 1 soaked).
pub fn parse_wetness(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(w) if (0.0..=1.0).contains(&w) => Ok(w),
        _ => Err(format!("expected a wetness from 0 (dry) to 1 (soaked), got {text:?}")),
    }
}

pub fn parse_vec3(text: &str) -> Result<Vec3, String> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{text:?}: {e}"))?;
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("expected three numbers x,y,z, got {text:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_vectors_parse() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert!(parse_size("0x5").unwrap_err().contains("from 1 to 16384"));
        assert!(parse_size("16385x5").is_err());
        assert!(parse_size("big").is_err());
        assert_eq!(parse_msaa("4"), Ok(4));
        assert!(parse_msaa("3").is_err());
        assert_eq!(parse_vec3("1,-2, 3.5"), Ok(Vec3::new(1.0, -2.0, 3.5)));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,nan,2").is_err());
    }
}
