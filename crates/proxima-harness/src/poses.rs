//! The pose-file format [sources: pose-format] of `proxima collide`, `proxima
//! render` and the W5 benchmark: one rigid pose per line, 12 numbers (a row-major
//! rotation, then a translation), `#` comments and blank lines skipped.

use proxima::glam::{Affine3A, Mat3, Vec3};

/// Parses a pose file: one pose per line (12 numbers), `#` comments, blank lines.
/// Errors name the file and line (`NAME:LINE: what`). O(text).
pub fn parse(name: &str, text: &str) -> Result<Vec<Affine3A>, String> {
    let mut poses = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        if line.trim().is_empty() {
            continue;
        }
        let at = |msg: String| format!("{name}:{}: {msg}", i + 1);
        let nums: Vec<f32> = line
            .split_whitespace()
            .map(|t| {
                t.parse::<f32>()
                    .map_err(|_| at(format!("'{t}' is not a number")))
                    .and_then(|v| {
                        if v.is_finite() {
                            Ok(v)
                        } else {
                            Err(at(format!("'{t}' is not finite")))
                        }
                    })
            })
            .collect::<Result<_, _>>()?;
        if nums.len() != 12 {
            return Err(at(format!("expected 12 numbers, found {}", nums.len())));
        }
        // Row-major in the file; glam is column-major.
        let r = Mat3::from_cols_array(&[
            nums[0], nums[3], nums[6], nums[1], nums[4], nums[7], nums[2], nums[5], nums[8],
        ]);
        let pose = Affine3A::from_mat3_translation(r, Vec3::new(nums[9], nums[10], nums[11]));
        proxima::narrow::check_pose(&pose).map_err(|e| at(e.to_string()))?;
        poses.push(pose);
    }
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_file_parsing_and_errors() {
        let ok = "# header\n1 0 0 0 1 0 0 0 1 1 2 3\n\n0 -1 0 1 0 0 0 0 1 0 0 0 # z 90\n";
        let p = parse("p.txt", ok).unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!(Vec3::from(p[0].translation), Vec3::new(1.0, 2.0, 3.0));
        // Row-major: the second pose maps x to y.
        let x = p[1].transform_vector3(Vec3::X);
        assert!((x - Vec3::Y).length() < 1e-6);
        let e = parse("p.txt", "1 0 0 0 1 0 0 0 1 1 2\n").unwrap_err();
        assert!(e.starts_with("p.txt:1:"), "{e}");
        let e = parse("p.txt", "\n1 0 0 0 1 0 0 0 1 1 2 x\n").unwrap_err();
        assert!(e.starts_with("p.txt:2:"), "{e}");
        let e = parse("p.txt", "1 0 0 0 1 0 0 0 1 1 2 NaN\n").unwrap_err();
        assert!(e.starts_with("p.txt:1:"), "{e}");
        let e = parse("p.txt", "2 0 0 0 1 0 0 0 1 1 2 3\n").unwrap_err();
        assert!(e.starts_with("p.txt:1:") && e.contains("rotation"), "{e}");
    }
}
