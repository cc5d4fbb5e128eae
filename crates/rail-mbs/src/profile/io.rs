//! Profile file readers: plain two-column text and the SIMPACK `.prr`/`.prw` format.
//!
//! Both readers report malformed input as [`ProfileError::Parse`] with the file name
//! and 1-based line number; they never panic.

use super::{Profile, ProfileError};
use std::path::Path;

/// Reads a file as UTF-8 text; bytes that are not UTF-8 are a [`ProfileError::Parse`]
/// naming the line (malformed content, not an I/O failure).
fn read_text(path: &Path) -> Result<String, ProfileError> {
    let bytes = std::fs::read(path).map_err(|e| ProfileError::Io { path: path.display().to_string(), source: e })?;
    String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        ProfileError::Parse {
            file: path.display().to_string(),
            line: 1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count(),
            message: format!("not UTF-8 text (invalid byte 0x{:02x} at offset {offset})", bytes[offset]),
        }
    })
}

/// Reads a two-column text file of `y z` pairs (whitespace, comma or semicolon
/// separated). Empty lines and lines starting with `#`, `%`, `!` or `//` are skipped; a
/// trailing third column (weight) is ignored. Values are returned as written (no unit
/// or sign conversion).
pub fn read_two_column(path: impl AsRef<Path>) -> Result<Vec<(f64, f64)>, ProfileError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    parse_two_column(&text, &path.display().to_string())
}

/// Parses two-column text (see [`read_two_column`]); `label` names the source in errors.
pub fn parse_two_column(text: &str, label: &str) -> Result<Vec<(f64, f64)>, ProfileError> {
    let mut pts = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty()
            || line.starts_with('#')
            || line.starts_with('%')
            || line.starts_with('!')
            || line.starts_with("//")
        {
            continue;
        }
        pts.push(parse_pair(line, label, i + 1)?);
    }
    if pts.len() < 2 {
        return Err(ProfileError::Parse {
            file: label.to_string(),
            line: text.lines().count(),
            message: format!("expected at least 2 points, found {}", pts.len()),
        });
    }
    Ok(pts)
}

fn parse_pair(line: &str, label: &str, lineno: usize) -> Result<(f64, f64), ProfileError> {
    let fields: Vec<&str> =
        line.split(|c: char| c.is_whitespace() || c == ',' || c == ';').filter(|s| !s.is_empty()).collect();
    if fields.len() < 2 || fields.len() > 3 {
        return Err(ProfileError::Parse {
            file: label.to_string(),
            line: lineno,
            message: format!("expected 2 or 3 numbers, found {} fields: `{line}`", fields.len()),
        });
    }
    let num = |s: &str| -> Result<f64, ProfileError> {
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(ProfileError::Parse {
                file: label.to_string(),
                line: lineno,
                message: format!("`{s}` is not a finite number"),
            }),
        }
    };
    Ok((num(fields[0])?, num(fields[1])?))
}

/// Whether a SIMPACK profile file describes a rail or a wheel (`header.type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileKind {
    /// `type = 0` (`.prr`).
    Rail,
    /// `type = 1` (`.prw`).
    Wheel,
}

/// Contents of a SIMPACK rail/wheel profile file.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpackProfile {
    /// Source label (file name).
    pub source: String,
    /// Rail or wheel.
    pub kind: ProfileKind,
    /// `comment` field of the spline block (empty if absent).
    pub comment: String,
    /// Raw points `(y, z)` as written, in file length units (SIMPACK: `z` down).
    pub raw_points: Vec<(f64, f64)>,
    /// `units.len.f`: file length units per metre (1000 for mm).
    pub length_factor: f64,
    /// `mirror.y` flag.
    pub mirror_y: bool,
    /// `mirror.z` flag.
    pub mirror_z: bool,
    /// `shift.y`, `shift.z` in file units.
    pub shift: (f64, f64),
}

impl SimpackProfile {
    /// Converts to a [`Profile`] in the crate convention: applies the shift and the
    /// `mirror.y`/`mirror.z` flags as SIMPACK's pre-processing does, converts to metres
    /// and flips `z` to point up.
    pub fn to_profile(&self) -> Result<Profile, ProfileError> {
        let f = self.length_factor;
        let pts: Vec<(f64, f64)> = self
            .raw_points
            .iter()
            .map(|&(y, z)| {
                let (mut y, mut z) = (y + self.shift.0, z + self.shift.1);
                if self.mirror_y {
                    y = -y;
                }
                if self.mirror_z {
                    z = -z;
                }
                (y / f, -z / f)
            })
            .collect();
        Profile::from_points(&self.source, &pts)
    }
}

/// Reads a SIMPACK `.prr`/`.prw` profile file.
pub fn read_simpack(path: impl AsRef<Path>) -> Result<SimpackProfile, ProfileError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let name = path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_else(|| path.display().to_string());
    parse_simpack(&text, &name)
}

/// Parses SIMPACK profile text; `label` names the source in errors.
///
/// Supported: `header.type`, `spline.begin`…`spline.end` with `comment`, `shift.y`,
/// `shift.z`, `mirror.y`, `mirror.z`, `units.len.f`, `rotate` (must be 0), `bound.*`
/// (applied when min < max) and the `point.begin`…`point.end` block of `y z [weight]`
/// rows. `!` starts a comment anywhere on a line.
pub fn parse_simpack(text: &str, label: &str) -> Result<SimpackProfile, ProfileError> {
    let err = |line: usize, message: String| ProfileError::Parse { file: label.to_string(), line, message };
    let mut kind: Option<ProfileKind> = None;
    let mut comment = String::new();
    let mut length_factor = 1.0;
    let (mut mirror_y, mut mirror_z) = (false, false);
    let mut shift = (0.0, 0.0);
    let mut bounds = [1.0, 0.0, 1.0, 0.0];
    let mut in_points = false;
    let mut in_header = false;
    let mut seen_points = false;
    let mut closed = false;
    let mut raw = Vec::new();
    let mut last_line = 0;
    for (i, full) in text.lines().enumerate() {
        let lineno = i + 1;
        last_line = lineno;
        // Strip comments, but keep `!` inside quotes (comment strings).
        let line = strip_comment(full).trim();
        if line.is_empty() {
            continue;
        }
        if in_points {
            if line == "point.end" {
                in_points = false;
                closed = true;
                continue;
            }
            raw.push(parse_pair(line, label, lineno)?);
            continue;
        }
        if line == "header.begin" {
            in_header = true;
            continue;
        }
        if line == "header.end" {
            in_header = false;
            continue;
        }
        if line == "point.begin" {
            if seen_points {
                return Err(err(lineno, "second point.begin block".into()));
            }
            in_points = true;
            seen_points = true;
            continue;
        }
        if let Some((key, value)) = line.split_once('=') {
            let key = key.trim();
            let value = value.trim();
            let number = || -> Result<f64, ProfileError> {
                value
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| err(lineno, format!("value of `{key}` is not a number: `{value}`")))
            };
            match key {
                "type" if in_header => {
                    kind = Some(match number()? as i64 {
                        0 => ProfileKind::Rail,
                        1 => ProfileKind::Wheel,
                        t => return Err(err(lineno, format!("unknown profile type {t}"))),
                    })
                }
                "comment" => comment = value.trim_matches('\'').trim().to_string(),
                "units.len.f" => {
                    length_factor = number()?;
                    if length_factor <= 0.0 {
                        return Err(err(lineno, "units.len.f must be positive".into()));
                    }
                }
                "mirror.y" => mirror_y = number()? != 0.0,
                "mirror.z" => mirror_z = number()? != 0.0,
                "shift.y" => shift.0 = number()?,
                "shift.z" => shift.1 = number()?,
                "rotate" if number()? != 0.0 => {
                    return Err(err(lineno, "non-zero `rotate` is not supported".into()));
                }
                "bound.y.min" => bounds[0] = number()?,
                "bound.y.max" => bounds[1] = number()?,
                "bound.z.min" => bounds[2] = number()?,
                "bound.z.max" => bounds[3] = number()?,
                _ => {}
            }
        }
    }
    if in_points {
        return Err(err(last_line, "point.begin block is not closed by point.end".into()));
    }
    if !closed {
        return Err(err(last_line, "no point.begin … point.end block found".into()));
    }
    let kind = kind.ok_or_else(|| err(last_line, "header `type` (0 = rail, 1 = wheel) missing".into()))?;
    if bounds[0] < bounds[1] {
        raw.retain(|p: &(f64, f64)| p.0 >= bounds[0] && p.0 <= bounds[1]);
    }
    if bounds[2] < bounds[3] {
        raw.retain(|p: &(f64, f64)| p.1 >= bounds[2] && p.1 <= bounds[3]);
    }
    if raw.len() < 2 {
        return Err(err(last_line, format!("expected at least 2 profile points, found {}", raw.len())));
    }
    Ok(SimpackProfile {
        source: label.to_string(),
        kind,
        comment,
        raw_points: raw,
        length_factor,
        mirror_y,
        mirror_z,
        shift,
    })
}

fn strip_comment(line: &str) -> &str {
    let mut in_quote = false;
    for (i, c) in line.char_indices() {
        match c {
            '\'' => in_quote = !in_quote,
            '!' if !in_quote => return &line[..i],
            _ => {}
        }
    }
    line
}
