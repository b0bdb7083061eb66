//! A Mitsuba XML file as a tree of elements, each with its line and
//! column: the one place `roxmltree` is used. Comments, processing
//! instructions and whitespace are dropped; text inside an element is
//! not part of Mitsuba's format and is reported once.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sahara_readers::FormatError;

use crate::common::gzip::read_maybe_gz;
use crate::common::position::Loc;
use crate::common::warnings::Warnings;

/// Largest number of XML nodes read from one file (roxmltree's own limit
/// is 2^32): a guard against a runaway file, far above real scenes.
const MAX_NODES: u32 = 1 << 26;

/// An element of a scene file.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Node {
    /// The tag: `shape`, `float`, `transform` ...
    pub(crate) tag: String,
    /// The attributes in file order, `$name` references not yet replaced.
    pub(crate) attrs: Vec<(String, String)>,
    /// The elements inside, in file order.
    pub(crate) children: Vec<Node>,
    /// Where the element starts (its `<`).
    pub(crate) loc: Loc,
    /// The folder of the file the element is written in (relative file
    /// names resolve against it).
    pub(crate) folder: Arc<PathBuf>,
}

impl Node {
    /// The value of attribute `name`, if given.
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The value of attribute `name`, or an error naming the element.
    pub(crate) fn need(&self, name: &str) -> Result<&str, FormatError> {
        self.attr(name).ok_or_else(|| {
            self.loc
                .error(format!("<{}> needs a '{name}' attribute", self.tag))
        })
    }

    /// An error at this element.
    pub(crate) fn error(&self, message: impl std::fmt::Display) -> FormatError {
        self.loc.error(message)
    }
}

/// Reads the file `path` (gzip-compressed or not) as a tree; `name` is
/// what messages call it.
pub(crate) fn read_file(path: &Path, name: &str, w: &mut Warnings) -> Result<Node, FormatError> {
    let bytes = read_maybe_gz(path)?;
    let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
    parse_text(&bytes, name, &folder, w)
}

/// Parses the text of a file called `name` whose folder is `folder`.
pub(crate) fn parse_text(
    bytes: &[u8],
    name: &str,
    folder: &Path,
    w: &mut Warnings,
) -> Result<Node, FormatError> {
    let file: Arc<str> = name.into();
    let at = |line: u32, col: u32| Loc {
        file: file.clone(),
        line,
        col,
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let before = &bytes[..e.valid_up_to()];
        let line = before.iter().filter(|&&b| b == b'\n').count() as u32 + 1;
        let col = before
            .rsplit(|&b| b == b'\n')
            .next()
            .map_or(0, |l| String::from_utf8_lossy(l).chars().count() as u32)
            + 1;
        at(line, col).error("the file is not UTF-8 text")
    })?;
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: MAX_NODES,
        ..roxmltree::ParsingOptions::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, options)
        .map_err(|e| xml_error(&e, text, &at))?;
    let folder = Arc::new(folder.to_path_buf());
    let mut text_at = None;
    let root = convert(&doc, doc.root_element(), &at, &folder, &mut text_at);
    if let Some(loc) = text_at {
        w.add(
            "text inside an element is not part of Mitsuba's format; ignored",
            &loc,
        );
    }
    Ok(root)
}

/// The tree under `e`.
fn convert(
    doc: &roxmltree::Document,
    e: roxmltree::Node,
    at: &impl Fn(u32, u32) -> Loc,
    folder: &Arc<PathBuf>,
    text_at: &mut Option<Loc>,
) -> Node {
    let pos = doc.text_pos_at(e.range().start);
    let mut children = Vec::new();
    for c in e.children() {
        if c.is_element() {
            children.push(convert(doc, c, at, folder, text_at));
        } else if c.is_text() && c.text().is_some_and(|t| !t.trim().is_empty()) && text_at.is_none()
        {
            let p = doc.text_pos_at(c.range().start);
            *text_at = Some(at(p.row, p.col));
        }
    }
    Node {
        tag: e.tag_name().name().to_owned(),
        attrs: e
            .attributes()
            .map(|a| (a.name().to_owned(), a.value().to_owned()))
            .collect(),
        children,
        loc: at(pos.row, pos.col),
        folder: folder.clone(),
    }
}

/// roxmltree's error as one line at its place (the end of the file for
/// an element left open).
fn xml_error(e: &roxmltree::Error, text: &str, at: &impl Fn(u32, u32) -> Loc) -> FormatError {
    use roxmltree::Error as E;
    let end = || {
        let line = text.lines().count().max(1) as u32;
        let col = text.lines().last().map_or(0, |l| l.chars().count() as u32) + 1;
        at(line, col)
    };
    match e {
        E::UnexpectedCloseTag(open, close, pos) => at(pos.row, pos.col).error(format!(
            "</{close}> closes <{open}>: <{open}> is not closed"
        )),
        E::UnexpectedEndOfStream | E::UnclosedRootNode => {
            end().error("the file ends inside an element that is not closed")
        }
        E::NoRootNode => {
            end().error("the file holds no element (expected <scene version=\"3.0.0\">)")
        }
        other => {
            let pos = other.pos();
            let message = other.to_string().replace(&format!(" at {pos}"), "");
            at(pos.row, pos.col).error(format!("not well-formed XML: {message}"))
        }
    }
}

#[cfg(test)]
impl Node {
    /// An element `<tag attrs.../>` of a file `t.xml` at `line`, `col`, for
    /// the tests of the modules that read elements.
    pub(crate) fn at(tag: &str, attrs: &[(&str, &str)], line: u32, col: u32) -> Node {
        Node {
            tag: tag.into(),
            attrs: attrs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            children: Vec::new(),
            loc: Loc {
                file: "t.xml".into(),
                line,
                col,
            },
            folder: Arc::new(PathBuf::new()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Node, FormatError> {
        parse_text(
            text.as_bytes(),
            "t.xml",
            Path::new("/f"),
            &mut Warnings::default(),
        )
    }

    #[test]
    fn elements_keep_their_places_and_attributes() {
        let n = parse("<scene version=\"3.0.0\">\n  <!-- c -->\n  <shape type=\"obj\">\n    <string name=\"filename\" value=\"a.obj\"/>\n  </shape>\n</scene>\n").unwrap();
        assert_eq!(n.tag, "scene");
        assert_eq!(n.attr("version"), Some("3.0.0"));
        let s = &n.children[0];
        assert_eq!((s.tag.as_str(), s.loc.line, s.loc.col), ("shape", 3, 3));
        assert_eq!(s.children[0].attr("value"), Some("a.obj"));
        assert_eq!(s.children[0].loc.line, 4);
        assert_eq!(*s.folder, PathBuf::from("/f"));
    }

    #[test]
    fn malformed_xml_is_one_line_at_its_place() {
        let e = parse("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.xml: line 3: column 1: </scene> closes <shape>: <shape> is not closed"
        );
        let e = parse("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.xml: line 2: column 24: the file ends inside an element that is not closed"
        );
        let e = parse(
            "<scene version=\"3.0.0\">\n <float name=\"x\" value=\"1\" value=\"2\"/></scene>",
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("t.xml: line 2: column "), "{e}");
        assert!(e.contains("not well-formed XML: attribute 'value'"), "{e}");
    }
}
