//! Camera sidecars: `<dir>/<stem>.camera.json` next to a mesh file.
//!
//! The JSON is `{"eye":[x,y,z],"target":[x,y,z],"up":[x,y,z],"vfov_deg":f}`;
//! `up` defaults to `[0,1,0]` and `vfov_deg` to 45. Unknown keys are an error
//! (so a typo such as `"vfov"` cannot silently give the default).

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::FormatError;

/// Default `up` when a sidecar has none.
pub const DEFAULT_UP: Vec3 = Vec3::Y;

/// Default vertical field of view, in degrees, when a sidecar has none.
pub const DEFAULT_VFOV_DEG: f32 = 45.0;

/// A pinhole camera stored next to a mesh: position, look-at point, up vector and vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "SidecarJson", into = "SidecarJson")]
pub struct CameraSidecar {
    /// Camera position.
    pub eye: Vec3,
    /// Point the camera looks at.
    pub target: Vec3,
    /// Up direction (need not be normalised or orthogonal to the view direction).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub vfov_deg: f32,
}

/// The JSON shape of a sidecar (glam's serde support is not enabled in the workspace).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SidecarJson {
    eye: [f32; 3],
    target: [f32; 3],
    #[serde(default = "default_up")]
    up: [f32; 3],
    #[serde(default = "default_vfov_deg")]
    vfov_deg: f32,
}

fn default_up() -> [f32; 3] {
    DEFAULT_UP.to_array()
}

fn default_vfov_deg() -> f32 {
    DEFAULT_VFOV_DEG
}

impl From<SidecarJson> for CameraSidecar {
    fn from(j: SidecarJson) -> Self {
        CameraSidecar {
            eye: Vec3::from_array(j.eye),
            target: Vec3::from_array(j.target),
            up: Vec3::from_array(j.up),
            vfov_deg: j.vfov_deg,
        }
    }
}

impl From<CameraSidecar> for SidecarJson {
    fn from(c: CameraSidecar) -> Self {
        SidecarJson {
            eye: c.eye.to_array(),
            target: c.target.to_array(),
            up: c.up.to_array(),
            vfov_deg: c.vfov_deg,
        }
    }
}

/// Path of the sidecar for a mesh file: `<dir>/<stem>.camera.json`.
pub fn sidecar_path(mesh: &Path) -> PathBuf {
    let mut name = OsString::from(mesh.file_stem().unwrap_or_default());
    name.push(".camera.json");
    mesh.with_file_name(name)
}

/// Reads and checks a camera sidecar; errors name the file and, where possible, the line.
pub fn read_sidecar(path: &Path) -> Result<CameraSidecar, FormatError> {
    let text = fs::read_to_string(path).map_err(|e| FormatError::io(path, e))?;
    parse_sidecar(&text, &path.display().to_string())
}

/// Parses and checks sidecar JSON held in memory; `name` is used in error messages.
pub fn parse_sidecar(text: &str, name: &str) -> Result<CameraSidecar, FormatError> {
    let camera: CameraSidecar = serde_json::from_str(text).map_err(|e| {
        let full = e.to_string();
        let position = format!(" at line {} column {}", e.line(), e.column());
        let what = full.strip_suffix(&position).unwrap_or(&full);
        FormatError::at_line(
            name,
            e.line().max(1),
            format!("column {}: invalid camera sidecar: {what}", e.column()),
        )
    })?;
    check(&camera, text, name)?;
    Ok(camera)
}

/// Rejects cameras the renderer cannot use (non-finite values, eye == target,
/// up parallel to the view direction, field of view outside (0, 180)).
fn check(c: &CameraSidecar, text: &str, name: &str) -> Result<(), FormatError> {
    let fail = |key: &str, message: String| match line_of_key(text, key) {
        Some(line) => FormatError::at_line(name, line, message),
        None => FormatError::in_file(name, message),
    };
    for (key, v) in [("eye", c.eye), ("target", c.target), ("up", c.up)] {
        if !v.is_finite() {
            return Err(fail(key, format!("{key} {v} is not finite")));
        }
    }
    if !(c.vfov_deg.is_finite() && c.vfov_deg > 0.0 && c.vfov_deg < 180.0) {
        return Err(fail(
            "vfov_deg",
            format!(
                "vfov_deg is {} but must be between 0 and 180 degrees (exclusive)",
                c.vfov_deg
            ),
        ));
    }
    let view = c.target - c.eye;
    if view.length_squared() == 0.0 {
        return Err(fail(
            "target",
            format!("eye and target are the same point {}", c.eye),
        ));
    }
    let up_len = c.up.length();
    if up_len == 0.0 || view.normalize().cross(c.up / up_len).length() < 1e-6 {
        return Err(fail(
            "up",
            format!(
                "up {} is zero or parallel to the view direction {}",
                c.up, view
            ),
        ));
    }
    Ok(())
}

/// 1-based line of the first `"key"` in `text`, if any.
fn line_of_key(text: &str, key: &str) -> Option<usize> {
    let quoted = format!("\"{key}\"");
    let at = text.find(&quoted)?;
    Some(1 + text[..at].matches('\n').count())
}
