//! Runs the directives of a pbrt file (and the files it includes) into a
//! [`Declarations`]: the graphics state stack, the transforms at the two
//! times of `TransformTimes`, named coordinate systems, materials,
//! textures and object definitions.
//!
//! Relative file names (in `Include`, `Import`, and shape, texture and
//! light parameters) are looked up first in the folder of the file the
//! parse started from (pbrt's rule), then in the folder of the file that
//! names them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DMat4, DVec3};
use sahara_readers::FormatError;

use super::declarations::{
    Declarations, Entity, InstanceDecl, LightDecl, MaterialRef, MediaDecl, MediumDecl, ShapeDecl,
    TextureDecl, Xform,
};
use super::lexer::{Lexer, Token, TokenKind};
use super::params::{Param, ParamList, Values};
use crate::common::gzip::read_maybe_gz;
use crate::common::position::Loc;
use crate::common::warnings::Warnings;

/// Deepest `Include` nesting accepted (a file including itself is caught by this).
const MAX_INCLUDE_DEPTH: usize = 32;

/// Deepest `AttributeBegin` nesting accepted.
const MAX_NESTING: usize = 10_000;

/// What a graphics state block saved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Block {
    Attribute,
    Transform,
    Object,
}

/// The graphics state.
#[derive(Clone, Debug)]
struct State {
    ctm: Xform,
    reverse: bool,
    material: MaterialRef,
    area_light: Option<Entity>,
    /// The `MediumInterface` in effect, if one was given.
    media: Option<MediaDecl>,
    /// `Attribute` defaults by target (`shape`, `light`, `material`, `medium`, `texture`).
    attributes: HashMap<String, Vec<Param>>,
}

/// The parser: a stack of open files and the state of the directives run so far.
pub(crate) struct Parser<'w> {
    files: Vec<(Lexer, PathBuf)>,
    peeked: Option<Token>,
    main_folder: PathBuf,
    state: State,
    stack: Vec<(State, Block, Loc)>,
    active: [bool; 2],
    named_coordinates: HashMap<String, Xform>,
    object: Option<(String, Vec<super::declarations::ShapeDecl>, Loc)>,
    out: Declarations,
    warnings: &'w mut Warnings,
}

/// Parses the file at `path` and everything it includes.
pub(crate) fn parse_file(
    path: &Path,
    warnings: &mut Warnings,
) -> Result<Declarations, FormatError> {
    let bytes = read_maybe_gz(path)?;
    let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
    parse_bytes(bytes, &path.display().to_string(), &folder, warnings)
}

/// Parses a file held in memory; `name` is used in messages and relative
/// names resolve against `folder`.
pub(crate) fn parse_bytes(
    bytes: Vec<u8>,
    name: &str,
    folder: &Path,
    warnings: &mut Warnings,
) -> Result<Declarations, FormatError> {
    let identity = Xform {
        m: [DMat4::IDENTITY; 2],
    };
    let mut p = Parser {
        files: vec![(Lexer::new(bytes, Arc::from(name)), folder.to_path_buf())],
        peeked: None,
        main_folder: folder.to_path_buf(),
        state: State {
            ctm: identity,
            reverse: false,
            material: MaterialRef::Default,
            area_light: None,
            media: None,
            attributes: HashMap::new(),
        },
        stack: Vec::new(),
        active: [true, true],
        named_coordinates: HashMap::new(),
        object: None,
        out: Declarations {
            transform_times: (0.0, 1.0),
            ..Declarations::default()
        },
        warnings,
    };
    p.run()?;
    for (_, block, loc) in &p.stack {
        let what = match block {
            Block::Attribute => "AttributeBegin without AttributeEnd",
            Block::Transform => "TransformBegin without TransformEnd",
            Block::Object => "ObjectBegin without ObjectEnd",
        };
        p.warnings.add(what, loc);
    }
    if let Some((name, shapes, loc)) = p.object.take() {
        p.out.objects.insert(name, (shapes, loc));
    }
    Ok(p.out)
}

/// A number written as a bare word.
fn number(t: &Token) -> Result<f64, FormatError> {
    match &t.kind {
        TokenKind::Word(w) => w
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| t.loc.error(format!("expected a number, found '{w}'"))),
        TokenKind::Str(s) => Err(t.loc.error(format!("expected a number, found \"{s}\""))),
        TokenKind::Open => Err(t.loc.error("expected a number, found '['")),
        TokenKind::Close => Err(t.loc.error("expected a number, found ']'")),
    }
}

impl Parser<'_> {
    fn next(&mut self) -> Result<Option<Token>, FormatError> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        while let Some((lexer, _)) = self.files.last_mut() {
            if let Some(t) = lexer.next_token()? {
                return Ok(Some(t));
            }
            self.files.pop();
        }
        Ok(None)
    }

    fn peek(&mut self) -> Result<Option<&Token>, FormatError> {
        if self.peeked.is_none() {
            self.peeked = self.next()?;
        }
        Ok(self.peeked.as_ref())
    }

    /// The next token, which the directive at `after` needs.
    fn need(&mut self, after: &Loc, what: &str) -> Result<Token, FormatError> {
        self.next()?
            .ok_or_else(|| after.error(format!("the file ends where {what} is expected")))
    }

    fn string(&mut self, after: &Loc, what: &str) -> Result<String, FormatError> {
        let t = self.need(after, what)?;
        match t.kind {
            TokenKind::Str(s) => Ok(s),
            _ => Err(t.loc.error(format!("expected {what} (a quoted string)"))),
        }
    }

    fn numbers<const N: usize>(
        &mut self,
        after: &Loc,
        what: &str,
    ) -> Result<[f64; N], FormatError> {
        let mut out = [0.0; N];
        for v in &mut out {
            let t = self.need(after, what)?;
            *v = number(&t)?;
        }
        Ok(out)
    }

    /// 16 numbers, bracketed or not.
    fn matrix(&mut self, after: &Loc) -> Result<DMat4, FormatError> {
        let bracketed = matches!(self.peek()?, Some(t) if t.kind == TokenKind::Open);
        if bracketed {
            self.next()?;
        }
        let m: [f64; 16] = self.numbers(after, "16 matrix values")?;
        if bracketed {
            let t = self.need(after, "']'")?;
            if t.kind != TokenKind::Close {
                return Err(t.loc.error("expected ']' after 16 matrix values"));
            }
        }
        // The file lists the matrix column by column (translation last).
        Ok(DMat4::from_cols_array(&m))
    }

    /// The parameter list after a directive's fixed arguments.
    fn params(&mut self) -> Result<Vec<Param>, FormatError> {
        let mut out = Vec::new();
        while let Some(Token {
            kind: TokenKind::Str(_),
            ..
        }) = self.peek()?
        {
            let t = self.next()?.expect("peeked");
            let TokenKind::Str(decl) = t.kind else {
                unreachable!()
            };
            let values = self.values(&t.loc, &decl)?;
            out.push(Param::new(&decl, values, t.loc)?);
        }
        Ok(out)
    }

    fn values(&mut self, decl_loc: &Loc, decl: &str) -> Result<Values, FormatError> {
        let what = format!("the value of \"{decl}\"");
        let first = self.need(decl_loc, &what)?;
        let mut tokens = Vec::new();
        match first.kind {
            TokenKind::Open => loop {
                let t = self.need(decl_loc, "']'")?;
                match t.kind {
                    TokenKind::Close => break,
                    TokenKind::Open => return Err(t.loc.error("'[' inside an array")),
                    _ => tokens.push(t),
                }
            },
            TokenKind::Close => {
                return Err(first.loc.error(format!("']' where {what} is expected")))
            }
            _ => tokens.push(first),
        }
        let mut nums = Vec::new();
        let mut strs = Vec::new();
        let mut bools = Vec::new();
        for t in &tokens {
            match &t.kind {
                TokenKind::Str(s) => strs.push(s.clone()),
                TokenKind::Word(w) if w == "true" || w == "false" => bools.push(w == "true"),
                _ => nums.push(number(t)?),
            }
            if [nums.len(), strs.len(), bools.len()]
                .iter()
                .filter(|&&n| n > 0)
                .count()
                > 1
            {
                return Err(t
                    .loc
                    .error(format!("{what} mixes numbers, strings and booleans")));
            }
        }
        Ok(if !strs.is_empty() {
            Values::Str(strs)
        } else if !bools.is_empty() {
            Values::Bool(bools)
        } else {
            Values::Num(nums)
        })
    }

    fn folders(&self) -> Vec<PathBuf> {
        let mut out = vec![self.main_folder.clone()];
        if let Some((_, f)) = self.files.last() {
            if *f != self.main_folder {
                out.push(f.clone());
            }
        }
        out
    }

    /// An entity of kind `kind` with the parameters that follow and the
    /// `Attribute` defaults of `target`.
    fn entity(&mut self, kind: String, loc: Loc, target: &str) -> Result<Entity, FormatError> {
        let params = ParamList::new(self.params()?)?;
        let params = match self.state.attributes.get(target) {
            Some(d) => params.with_defaults(d),
            None => params,
        };
        Ok(Entity {
            kind,
            params,
            loc,
            folders: self.folders(),
        })
    }

    /// Applies `f` to the active matrices of the CTM.
    fn apply(&mut self, f: impl Fn(DMat4) -> DMat4) {
        for i in 0..2 {
            if self.active[i] {
                self.state.ctm.m[i] = f(self.state.ctm.m[i]);
            }
        }
    }

    fn push(&mut self, block: Block, loc: Loc) -> Result<(), FormatError> {
        if self.stack.len() >= MAX_NESTING {
            return Err(loc.error(format!("blocks nested more than {MAX_NESTING} deep")));
        }
        self.stack.push((self.state.clone(), block, loc));
        Ok(())
    }

    fn pop(&mut self, block: Block, loc: &Loc, name: &str) -> Result<(), FormatError> {
        match self.stack.last() {
            Some((_, b, _)) if *b == block => {}
            Some((_, _, open)) => {
                return Err(loc.error(format!(
                    "{name} does not close the block opened at {}",
                    open.short()
                )))
            }
            None => return Err(loc.error(format!("{name} without a block to close"))),
        }
        let (saved, _, _) = self.stack.pop().expect("checked");
        if block == Block::Transform {
            self.state.ctm = saved.ctm;
        } else {
            self.state = saved;
        }
        Ok(())
    }

    fn include(&mut self, loc: &Loc, file: &str) -> Result<(), FormatError> {
        if self.files.len() >= MAX_INCLUDE_DEPTH {
            return Err(loc.error(format!(
                "includes nested more than {MAX_INCLUDE_DEPTH} deep (does a file include itself?)"
            )));
        }
        let path = resolve(&self.folders(), file);
        let bytes = read_maybe_gz(&path).map_err(|e| loc.error(format!("Include: {e}")))?;
        let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
        // The token after the directive was not peeked (Include takes no parameters).
        debug_assert!(self.peeked.is_none());
        self.files.push((
            Lexer::new(bytes, Arc::from(path.display().to_string())),
            folder,
        ));
        Ok(())
    }

    fn run(&mut self) -> Result<(), FormatError> {
        while let Some(t) = self.next()? {
            let loc = t.loc.clone();
            let TokenKind::Word(directive) = t.kind else {
                return Err(loc.error(match t.kind {
                    TokenKind::Str(s) => format!("expected a directive, found \"{s}\""),
                    _ => "expected a directive, found a bracket".to_owned(),
                }));
            };
            self.directive(&directive, loc)?;
        }
        Ok(())
    }

    /// Applies one directive at `loc` to the graphics state or the
    /// declarations.
    ///
    /// One piece on purpose: it is the parser's one table of pbrt's
    /// directives, an arm per directive, most of them a few lines; split
    /// by directive, the graphics state would be passed to each.
    fn directive(&mut self, directive: &str, loc: Loc) -> Result<(), FormatError> {
        match directive {
            "Identity" => self.apply(|_| DMat4::IDENTITY),
            "Translate" => {
                let [x, y, z] = self.numbers(&loc, "3 numbers")?;
                self.apply(|m| m * DMat4::from_translation(DVec3::new(x, y, z)));
            }
            "Scale" => {
                let [x, y, z] = self.numbers(&loc, "3 numbers")?;
                self.apply(|m| m * DMat4::from_scale(DVec3::new(x, y, z)));
            }
            "Rotate" => {
                let [a, x, y, z] = self.numbers(&loc, "4 numbers")?;
                let axis = DVec3::new(x, y, z);
                if axis.length_squared() == 0.0 {
                    return Err(loc.error("Rotate about a zero axis"));
                }
                let r = DMat4::from_axis_angle(axis.normalize(), a.to_radians());
                self.apply(|m| m * r);
            }
            "LookAt" => {
                let v: [f64; 9] = self.numbers(&loc, "9 numbers")?;
                let r = look_at(
                    DVec3::new(v[0], v[1], v[2]),
                    DVec3::new(v[3], v[4], v[5]),
                    DVec3::new(v[6], v[7], v[8]),
                )
                .ok_or_else(|| {
                    loc.error("LookAt: the eye is the target or the up vector is along the view")
                })?;
                self.apply(|m| m * r);
            }
            "Transform" => {
                let t = self.matrix(&loc)?;
                self.apply(|_| t);
            }
            "ConcatTransform" => {
                let t = self.matrix(&loc)?;
                self.apply(|m| m * t);
            }
            "CoordinateSystem" => {
                let name = self.string(&loc, "a name")?;
                self.named_coordinates.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = self.string(&loc, "a name")?;
                match self.named_coordinates.get(&name) {
                    Some(x) => self.state.ctm = *x,
                    None => {
                        return Err(loc.error(format!(
                            "CoordSysTransform: unknown coordinate system \"{name}\""
                        )))
                    }
                }
            }
            "TransformTimes" => {
                let [a, b] = self.numbers(&loc, "2 numbers")?;
                if b < a {
                    return Err(loc.error("TransformTimes: the end is before the start"));
                }
                self.out.transform_times = (a, b);
            }
            "ActiveTransform" => {
                let t = self.need(&loc, "StartTime, EndTime or All")?;
                self.active = match &t.kind {
                    TokenKind::Word(w) if w == "StartTime" => [true, false],
                    TokenKind::Word(w) if w == "EndTime" => [false, true],
                    TokenKind::Word(w) if w == "All" => [true, true],
                    _ => {
                        return Err(t
                            .loc
                            .error("ActiveTransform takes StartTime, EndTime or All"))
                    }
                };
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "WorldBegin" => {
                self.state.ctm = Xform {
                    m: [DMat4::IDENTITY; 2],
                };
                self.active = [true, true];
                self.named_coordinates
                    .insert("world".into(), self.state.ctm);
            }
            "WorldEnd" => {}
            "AttributeBegin" => self.push(Block::Attribute, loc)?,
            "AttributeEnd" => self.pop(Block::Attribute, &loc, "AttributeEnd")?,
            "TransformBegin" => self.push(Block::Transform, loc)?,
            "TransformEnd" => self.pop(Block::Transform, &loc, "TransformEnd")?,
            "Attribute" => {
                let target =
                    self.string(&loc, "a target (shape, light, material, medium, texture)")?;
                if !["shape", "light", "material", "medium", "texture"].contains(&target.as_str()) {
                    return Err(loc.error(format!("Attribute: unknown target \"{target}\"")));
                }
                let params = self.params()?;
                let list = self.state.attributes.entry(target).or_default();
                for p in params {
                    list.retain(|q| q.name != p.name);
                    list.push(p);
                }
            }
            "ObjectBegin" => {
                let name = self.string(&loc, "an object name")?;
                if let Some((open, _, at)) = &self.object {
                    return Err(loc.error(format!(
                        "ObjectBegin \"{name}\" inside the definition of \"{open}\" (begun at {})",
                        at.short()
                    )));
                }
                self.push(Block::Object, loc.clone())?;
                self.object = Some((name, Vec::new(), loc));
            }
            "ObjectEnd" => {
                self.pop(Block::Object, &loc, "ObjectEnd")?;
                let (name, shapes, at) = self.object.take().expect("an Object block is open");
                if self.out.objects.contains_key(&name) {
                    self.warnings.add(
                        format!("object \"{name}\" defined again; the last definition is used"),
                        &at,
                    );
                }
                self.out.objects.insert(name, (shapes, at));
            }
            "ObjectInstance" => {
                let name = self.string(&loc, "an object name")?;
                if self.object.is_some() {
                    return Err(loc.error("ObjectInstance inside an object definition"));
                }
                self.out.instances.push(InstanceDecl {
                    name,
                    xform: self.state.ctm,
                    loc,
                });
            }
            "Camera" => {
                let kind = self.string(&loc, "a camera type")?;
                let e = self.entity(kind, loc, "camera")?;
                let ctm = self.state.ctm;
                let inv = Xform {
                    m: [ctm.m[0].inverse(), ctm.m[1].inverse()],
                };
                self.named_coordinates.insert("camera".into(), inv);
                self.out.camera = Some((e, ctm));
                // The camera sits in the medium outside the surfaces
                // declared with it.
                self.out.camera_medium = self.state.media.clone();
            }
            "Film" | "Sampler" | "PixelFilter" | "Integrator" => {
                let kind = self.string(&loc, "a type")?;
                let e = self.entity(kind, loc, "")?;
                let slot = match directive {
                    "Film" => &mut self.out.film,
                    "Sampler" => &mut self.out.sampler,
                    "PixelFilter" => &mut self.out.filter,
                    _ => &mut self.out.integrator,
                };
                *slot = Some(e);
            }
            "MakeNamedMedium" => {
                let name = self.string(&loc, "a medium name")?;
                let entity = self.entity(String::new(), loc, "medium")?;
                self.out.media.push(MediumDecl {
                    name,
                    entity,
                    xform: self.state.ctm,
                });
            }
            "Accelerator" => {
                self.string(&loc, "a name")?;
                self.params()?;
                self.out.ignored.push((directive.to_owned(), loc));
            }
            "ColorSpace" => {
                let name = self.string(&loc, "a colour space name")?;
                if name != "srgb" {
                    self.out
                        .ignored
                        .push((format!("ColorSpace \"{name}\""), loc));
                }
            }
            "Option" => {
                self.params()?;
                self.out.ignored.push(("Option".into(), loc));
            }
            "MediumInterface" => {
                let inside = self.string(&loc, "a medium name")?;
                // One name: the same medium on both sides.
                let outside = match self.peek()? {
                    Some(Token {
                        kind: TokenKind::Str(_),
                        ..
                    }) => self.string(&loc, "a medium name")?,
                    _ => inside.clone(),
                };
                self.state.media = Some(MediaDecl {
                    inside,
                    outside,
                    loc,
                });
            }
            "Material" => {
                let kind = self.string(&loc, "a material type")?;
                let e = self.entity(kind, loc, "material")?;
                self.out.materials.push(e);
                self.state.material = MaterialRef::Anonymous(self.out.materials.len() - 1);
            }
            "MakeNamedMaterial" => {
                let name = self.string(&loc, "a material name")?;
                let e = self.entity(String::new(), loc, "material")?;
                self.out.named_materials.insert(name, e);
            }
            "NamedMaterial" => {
                let name = self.string(&loc, "a material name")?;
                self.state.material = MaterialRef::Named(name, loc);
            }
            "Texture" => {
                let name = self.string(&loc, "a texture name")?;
                let ty = self.string(&loc, "a texture type (float or spectrum)")?;
                let float = match ty.as_str() {
                    "float" => true,
                    "spectrum" | "color" | "rgb" => false,
                    _ => {
                        return Err(loc.error(format!(
                            "Texture \"{name}\": type \"{ty}\" is neither float nor spectrum"
                        )))
                    }
                };
                let class = self.string(&loc, "a texture class")?;
                let entity = self.entity(class, loc, "texture")?;
                self.out
                    .textures
                    .insert((name, float), TextureDecl { entity });
            }
            "LightSource" => {
                let kind = self.string(&loc, "a light type")?;
                let entity = self.entity(kind, loc, "light")?;
                self.out.lights.push(LightDecl {
                    entity,
                    xform: self.state.ctm,
                });
            }
            "AreaLightSource" => {
                let kind = self.string(&loc, "an area light type")?;
                let e = self.entity(kind, loc, "light")?;
                self.state.area_light = Some(e);
            }
            "Shape" => {
                let kind = self.string(&loc, "a shape type")?;
                let entity = self.entity(kind, loc, "shape")?;
                let decl = ShapeDecl {
                    entity,
                    xform: self.state.ctm,
                    reverse: self.state.reverse,
                    material: self.state.material.clone(),
                    area_light: self.state.area_light.clone(),
                    media: self.state.media.clone(),
                };
                match &mut self.object {
                    Some((_, shapes, _)) => shapes.push(decl),
                    None => self.out.shapes.push(decl),
                }
            }
            "Include" | "Import" => {
                let file = self.string(&loc, "a file name")?;
                self.include(&loc, &file)?;
            }
            other => return Err(loc.error(format!("unknown directive '{other}'"))),
        }
        Ok(())
    }
}

/// `file` looked up in `folders` in order: the first that exists, else the
/// first folder's (so that the error names it).
pub(crate) fn resolve(folders: &[PathBuf], file: &str) -> PathBuf {
    let p = Path::new(file);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    folders
        .iter()
        .map(|f| f.join(p))
        .find(|c| c.exists())
        .unwrap_or_else(|| folders.first().map_or(p.to_path_buf(), |f| f.join(p)))
}

/// pbrt's `LookAt`: the world-to-camera matrix of a camera at `eye` looking
/// at `target`, camera +x = up x forward, +y up, +z forward (pbrt's
/// left-handed camera space).
pub(crate) fn look_at(eye: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - eye).try_normalize()?;
    let right = up.try_normalize()?.cross(dir).try_normalize()?;
    let new_up = dir.cross(right);
    let camera_to_world = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        eye.extend(1.0),
    );
    Some(camera_to_world.inverse())
}
