//! The text header of a PLY file: encoding, elements and their properties.

use crate::error::FormatError;

/// How the body after `end_header` is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// Whitespace-separated numbers.
    Ascii,
    /// Packed little-endian values.
    BinaryLittleEndian,
    /// Packed big-endian values.
    BinaryBigEndian,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    /// The type named `name`, in either the classic or the sized spelling.
    fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary body.
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Whether the type holds integers.
    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// Smallest and largest value of an integer type.
    pub(crate) fn int_range(self) -> (i64, i64) {
        match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => (i64::MIN, i64::MAX),
        }
    }

    /// The classic PLY name of the type.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }
}

/// What a property holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// One value.
    Scalar(Scalar),
    /// A length of type `count`, then that many values of type `item`.
    List { count: Scalar, item: Scalar },
}

/// One `property` line.
#[derive(Clone, Debug)]
pub(crate) struct Property {
    pub(crate) name: String,
    pub(crate) kind: Kind,
}

/// One `element` line and its properties.
#[derive(Clone, Debug)]
pub(crate) struct Element {
    pub(crate) name: String,
    pub(crate) count: u64,
    pub(crate) properties: Vec<Property>,
    /// 1-based header line of the `element` line.
    pub(crate) line: usize,
}

/// A parsed header.
#[derive(Clone, Debug)]
pub(crate) struct Header {
    pub(crate) encoding: Encoding,
    pub(crate) elements: Vec<Element>,
    /// Byte offset of the first body byte.
    pub(crate) body_offset: usize,
    /// 1-based line number of the first body line (for ascii bodies).
    pub(crate) body_line: usize,
}

/// `bytes` shown for a message, cut short if long.
pub(crate) fn shown(bytes: &[u8]) -> String {
    const MAX: usize = 60;
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(MAX)]);
    if bytes.len() > MAX {
        format!("{text}...")
    } else {
        text.into_owned()
    }
}

/// Parses the header at the start of `bytes`; `name` is used in error messages.
///
/// One piece: a single pass over the header's lines, whose arms share the
/// pass's state (the line number every error names, the element whose
/// properties follow), checking each count before anything is allocated.
pub(crate) fn parse_header(bytes: &[u8], name: &str) -> Result<Header, FormatError> {
    let err = |line: usize, message: String| FormatError::at_line(name, line, message);
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut pos = 0;
    let mut line_no: usize = 0;
    loop {
        line_no += 1;
        if pos >= bytes.len() {
            return Err(err(
                line_no.saturating_sub(1).max(1),
                if line_no == 1 {
                    "the file is empty; a PLY file starts with a 'ply' line".to_owned()
                } else {
                    "the header has no 'end_header' line".to_owned()
                },
            ));
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let line = &bytes[pos..end];
        pos = (end + 1).min(bytes.len());
        let words: Vec<&[u8]> = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty())
            .collect();
        if line_no == 1 {
            if words != [b"ply"] {
                return Err(err(
                    1,
                    format!(
                        "not a PLY file: the first line must be 'ply' but is '{}'",
                        shown(line.trim_ascii())
                    ),
                ));
            }
            continue;
        }
        let Some((&keyword, args)) = words.split_first() else {
            continue;
        };
        match keyword {
            b"comment" | b"obj_info" => {}
            b"format" => {
                if encoding.is_some() {
                    return Err(err(line_no, "second 'format' line".to_owned()));
                }
                encoding = Some(match args.first().copied() {
                    Some(b"ascii") => Encoding::Ascii,
                    Some(b"binary_little_endian") => Encoding::BinaryLittleEndian,
                    Some(b"binary_big_endian") => Encoding::BinaryBigEndian,
                    other => {
                        return Err(err(
                            line_no,
                            format!(
                                "unknown PLY format '{}'; expected ascii, binary_little_endian or binary_big_endian",
                                shown(other.unwrap_or_default())
                            ),
                        ))
                    }
                });
            }
            b"element" => {
                let [element, count] = args else {
                    return Err(err(
                        line_no,
                        format!(
                            "expected 'element <name> <count>' but found '{}'",
                            shown(line.trim_ascii())
                        ),
                    ));
                };
                let count = std::str::from_utf8(count)
                    .ok()
                    .and_then(|c| c.parse::<u64>().ok())
                    .ok_or_else(|| {
                        err(
                            line_no,
                            format!(
                                "element '{}' has count '{}', which is not a non-negative integer",
                                shown(element),
                                shown(count)
                            ),
                        )
                    })?;
                elements.push(Element {
                    name: String::from_utf8_lossy(element).into_owned(),
                    count,
                    properties: Vec::new(),
                    line: line_no,
                });
            }
            b"property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(err(
                        line_no,
                        "'property' line before any 'element' line".to_owned(),
                    ));
                };
                let property = parse_property(args).map_err(|m| err(line_no, m))?;
                element.properties.push(property);
            }
            b"end_header" => {
                let Some(encoding) = encoding else {
                    return Err(err(
                        line_no,
                        "the header has no 'format' line before 'end_header'".to_owned(),
                    ));
                };
                return Ok(Header {
                    encoding,
                    elements,
                    body_offset: pos,
                    body_line: line_no + 1,
                });
            }
            other => {
                return Err(err(
                    line_no,
                    format!(
                        "unknown header keyword '{}' (expected format, comment, obj_info, element, property or end_header)",
                        shown(other)
                    ),
                ))
            }
        }
    }
}

/// Parses the words after `property`.
fn parse_property(args: &[&[u8]]) -> Result<Property, String> {
    let scalar = |word: &[u8]| {
        Scalar::from_name(word).ok_or_else(|| {
            format!(
                "unknown property type '{}' (expected char, uchar, short, ushort, int, uint, float, double or int8 ... float64)",
                shown(word)
            )
        })
    };
    match args {
        [b"list", count, item, name] => {
            let count = scalar(count)?;
            let item = scalar(item)?;
            if !count.is_integer() {
                return Err(format!(
                    "list property '{}' has length type {}; it must be an integer type",
                    shown(name),
                    count.name()
                ));
            }
            Ok(Property {
                name: String::from_utf8_lossy(name).into_owned(),
                kind: Kind::List { count, item },
            })
        }
        [ty, name] if *ty != b"list" => Ok(Property {
            name: String::from_utf8_lossy(name).into_owned(),
            kind: Kind::Scalar(scalar(ty)?),
        }),
        _ => Err(format!(
            "expected 'property <type> <name>' or 'property list <count type> <item type> <name>' but found 'property {}'",
            shown(&args.join(&b' '))
        )),
    }
}
