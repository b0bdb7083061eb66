//! Turning a tobj error into a message with a line number.
//!
//! tobj reports what went wrong but not where. Only when loading has failed,
//! the file is scanned again applying tobj's rule for that kind of error, and
//! the first line that breaks it is reported. If none is found (which should
//! not happen for the kinds below) the message says the line is unknown.

use tobj::LoadError;

use crate::error::FormatError;

/// A [`FormatError`] for tobj's `error` on the file `bytes` called `name`.
pub(super) fn describe(bytes: &[u8], name: &str, error: LoadError) -> FormatError {
    let what = summary(error);
    match find(bytes, error) {
        Some((line, detail)) => FormatError::at_line(name, line, format!("{what}: {detail}")),
        None => FormatError::in_file(
            name,
            format!("{what} (tobj gives no line number and no line breaking its rule was found)"),
        ),
    }
}

/// One phrase per tobj error kind, saying what the file must look like.
fn summary(error: LoadError) -> String {
    match error {
        LoadError::ReadError => "cannot read a line (the file must be UTF-8 text)",
        LoadError::PositionParseError => {
            "bad vertex ('v' needs three numbers, then optionally w or r g b)"
        }
        LoadError::ScalingByZeroError => "bad vertex (its w is 0)",
        LoadError::ColorParseError => {
            "bad vertex ('v x y z r g b' needs exactly three colour values)"
        }
        LoadError::NormalParseError => "bad normal ('vn' needs three numbers)",
        LoadError::TexcoordParseError => "bad texture coordinate ('vt' needs two numbers)",
        LoadError::FaceParseError => {
            "bad face (corners must be v, v/vt, v//vn or v/vt/vn with integer indices)"
        }
        LoadError::MaterialParseError => "bad 'usemtl' (the material name is missing)",
        LoadError::FaceVertexOutOfBounds => "face refers to a vertex that does not exist",
        LoadError::FaceTexCoordOutOfBounds => {
            "face refers to a texture coordinate that does not exist"
        }
        LoadError::FaceNormalOutOfBounds => "face refers to a normal that does not exist",
        LoadError::FaceColorOutOfBounds => {
            "face uses a vertex without a colour while earlier vertices have colours"
        }
        other => return format!("OBJ error: {other}"),
    }
    .to_owned()
}

/// 1-based line number and detail of the first line breaking `error`'s rule.
fn find(bytes: &[u8], error: LoadError) -> Option<(usize, String)> {
    match error {
        LoadError::ReadError => lines(bytes)
            .find(|(_, line)| std::str::from_utf8(line).is_err())
            .map(|(n, _)| (n, "this line is not valid UTF-8".to_owned())),
        LoadError::FaceVertexOutOfBounds => out_of_bounds(bytes, Part::Vertex),
        LoadError::FaceTexCoordOutOfBounds => out_of_bounds(bytes, Part::TexCoord),
        LoadError::FaceNormalOutOfBounds => out_of_bounds(bytes, Part::Normal),
        _ => lines(bytes).find_map(|(n, line)| {
            let (kind, detail) = syntax_error(std::str::from_utf8(line).ok()?)?;
            (kind == error).then_some((n, detail))
        }),
    }
}

/// The file's lines, numbered from 1.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, line)| (i + 1, line))
}

/// `text`, trimmed and cut short for a message.
fn clip(text: &str) -> String {
    const MAX: usize = 60;
    let text = text.trim();
    match text.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}...", &text[..cut]),
        None => text.to_owned(),
    }
}

/// Which tobj error (and why) a single statement raises, by tobj's parsing rules.
fn syntax_error(text: &str) -> Option<(LoadError, String)> {
    let numbers = |words: &[&str], n: usize| {
        words.len() >= n && words[..n].iter().all(|w| w.parse::<f32>().is_ok())
    };
    let mut words = text.split_whitespace();
    let keyword = words.next()?;
    let args: Vec<&str> = words.collect();
    let shown = clip(text);
    match keyword {
        "v" => {
            if !numbers(&args, 3) {
                return Some((
                    LoadError::PositionParseError,
                    format!("'{shown}' does not start with three numbers"),
                ));
            }
            match &args[3..] {
                [] | [_, _, _] => None,
                [w] => match w.parse::<f32>() {
                    Err(_) => Some((
                        LoadError::PositionParseError,
                        format!("'{shown}': w '{w}' is not a number"),
                    )),
                    Ok(0.0) => Some((
                        LoadError::ScalingByZeroError,
                        format!("'{shown}' has w = 0"),
                    )),
                    Ok(_) => None,
                },
                extra => Some((
                    LoadError::ColorParseError,
                    format!(
                        "'{shown}' has {} values after x y z; expected 1 (w) or 3 (r g b)",
                        extra.len()
                    ),
                )),
            }
        }
        "vt" if !numbers(&args, 2) => Some((
            LoadError::TexcoordParseError,
            format!("'{shown}' does not start with two numbers"),
        )),
        "vn" if !numbers(&args, 3) => Some((
            LoadError::NormalParseError,
            format!("'{shown}' does not start with three numbers"),
        )),
        "f" => args.iter().find(|c| corner(c).is_none()).map(|c| {
            (
                LoadError::FaceParseError,
                format!(
                    "corner '{}' in '{shown}' is not v, v/vt, v//vn or v/vt/vn",
                    clip(c)
                ),
            )
        }),
        // tobj takes everything after the first space as the name.
        "usemtl"
            if text
                .split_once(' ')
                .is_none_or(|(_, m)| m.trim().is_empty()) =>
        {
            Some((
                LoadError::MaterialParseError,
                format!("'{shown}' has no material name"),
            ))
        }
        _ => None,
    }
}

/// The (up to three) indices of a face corner `v/vt/vn`, or `None` if malformed.
fn corner(token: &str) -> Option<[Option<isize>; 3]> {
    let mut out = [None; 3];
    for (i, part) in token.split('/').enumerate() {
        if !part.is_empty() {
            *out.get_mut(i)? = Some(part.parse().ok()?);
        }
    }
    Some(out)
}

/// Which index of a face corner.
#[derive(Clone, Copy)]
enum Part {
    Vertex,
    TexCoord,
    Normal,
}

impl Part {
    fn slot(self) -> usize {
        self as usize
    }

    fn keyword(self) -> &'static str {
        ["v", "vt", "vn"][self.slot()]
    }

    fn noun(self) -> &'static str {
        ["vertex", "texture coordinate", "normal"][self.slot()]
    }
}

/// First face corner whose `part` index is out of range: first against the
/// whole file, then (forward references) against what precedes the face.
fn out_of_bounds(bytes: &[u8], part: Part) -> Option<(usize, String)> {
    let text_lines = || lines(bytes).filter_map(|(n, l)| Some((n, std::str::from_utf8(l).ok()?)));
    let total = text_lines()
        .filter(|(_, l)| l.split_whitespace().next() == Some(part.keyword()))
        .count();
    for forward_only in [false, true] {
        let mut before = 0;
        for (n, line) in text_lines() {
            let mut words = line.split_whitespace();
            match words.next() {
                Some(k) if k == part.keyword() => before += 1,
                Some("f") => {
                    for token in words {
                        let Some(x) = corner(token).and_then(|c| c[part.slot()]) else {
                            continue;
                        };
                        let index = if x < 0 { before as isize + x } else { x - 1 };
                        let limit = if forward_only { before } else { total };
                        if (0..limit as isize).contains(&index) {
                            continue;
                        }
                        let noun = part.noun();
                        let detail = if x == 0 {
                            format!("corner '{token}' uses index 0; OBJ indices start at 1")
                        } else if x < 0 {
                            format!(
                                "corner '{token}' has relative index {x} but only {before} '{}' lines come before it",
                                part.keyword()
                            )
                        } else if forward_only {
                            format!(
                                "corner '{token}' refers to {noun} {x}, which is defined after this line ({before} before it)"
                            )
                        } else {
                            format!(
                                "corner '{token}' refers to {noun} {x} but the file has only {total} ('{}' lines)",
                                part.keyword()
                            )
                        };
                        return Some((n, detail));
                    }
                }
                _ => {}
            }
        }
    }
    None
}
