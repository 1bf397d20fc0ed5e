//! Parameter lists (`"float fov" 40`, `"point3 P" [ ... ]`): read once, looked up by
//! name and type; parameters nobody asked for are reported as warnings.

use std::cell::Cell;

use super::lexer::{Lexer, Token};
use crate::error::Result;

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Values {
    Nums(Vec<f64>),
    Strs(Vec<String>),
    Bools(Vec<bool>),
}

#[derive(Debug)]
pub(super) struct Param {
    pub ty: String,
    pub name: String,
    pub values: Values,
    used: Cell<bool>,
}

/// The parameters of one statement, with the statement's name and place for messages.
#[derive(Debug)]
pub(super) struct Params {
    /// `origin:line`.
    pub loc: String,
    /// `Statement "type"`.
    pub what: String,
    pub list: Vec<Param>,
}

/// A warning: where (`origin:line`) and what (which does not name the place, so that
/// repeats can be counted rather than listed).
pub(super) type Warning = (String, String);

/// A colour parameter: an RGB triple, or a texture name (which hairtrace does not read).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Color {
    Rgb([f64; 3]),
    Texture(String),
}

/// Reads `"type name" value` pairs up to the next directive.
pub(super) fn read_params(lexer: &mut Lexer, loc: String, what: String) -> Result<Params> {
    let mut list: Vec<Param> = Vec::new();
    while let Some((Token::Str(_), _)) = lexer.peek()? {
        let Some((Token::Str(decl), line)) = lexer.next_token()? else {
            unreachable!("peeked a string");
        };
        let mut words = decl.split_whitespace();
        let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
            return Err(lexer.error(
                line,
                format_args!("parameter {decl:?}: expected \"type name\""),
            ));
        };
        let values = read_values(lexer, line, name)?;
        if list.iter().any(|p| p.name == name) {
            return Err(lexer.error(line, format_args!("parameter {name:?} given twice")));
        }
        list.push(Param {
            ty: ty.to_string(),
            name: name.to_string(),
            values,
            used: Cell::new(false),
        });
    }
    Ok(Params { loc, what, list })
}

/// One value, or a bracketed list of values of one kind.
fn read_values(lexer: &mut Lexer, line: u32, name: &str) -> Result<Values> {
    let single = |t: Token| match t {
        Token::Num(v) => Some(Values::Nums(vec![v])),
        Token::Str(s) => Some(Values::Strs(vec![s])),
        Token::Word("true") => Some(Values::Bools(vec![true])),
        Token::Word("false") => Some(Values::Bools(vec![false])),
        _ => None,
    };
    let missing = || format!("parameter {name:?} has no value");
    match lexer.next_token()? {
        Some((Token::Open, _)) => {
            let mut values: Option<Values> = None;
            loop {
                let Some((t, l)) = lexer.next_token()? else {
                    return Err(lexer.error(line, format_args!("parameter {name:?}: no `]`")));
                };
                if t == Token::Close {
                    return Ok(values.unwrap_or(Values::Nums(Vec::new())));
                }
                let mixed = || lexer.error(l, format_args!("parameter {name:?}: mixed values"));
                match (&mut values, t) {
                    (None, t) => values = Some(single(t).ok_or_else(mixed)?),
                    (Some(Values::Nums(v)), Token::Num(x)) => v.push(x),
                    (Some(Values::Strs(v)), Token::Str(s)) => v.push(s),
                    (Some(Values::Bools(v)), Token::Word("true")) => v.push(true),
                    (Some(Values::Bools(v)), Token::Word("false")) => v.push(false),
                    _ => return Err(mixed()),
                }
            }
        }
        Some((t, l)) => single(t).ok_or_else(|| lexer.error(l, missing())),
        None => Err(lexer.error(line, missing())),
    }
}

impl Params {
    fn find(&self, name: &str) -> Option<&Param> {
        let p = self.list.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    fn error(&self, p: &Param, message: impl std::fmt::Display) -> crate::Error {
        crate::Error::InvalidArg(format!(
            "{}: {}: parameter \"{} {}\": {message}",
            self.loc, self.what, p.ty, p.name
        ))
    }

    /// Marks `name` as read without reading it: parameters with no effect on our image.
    pub fn ignore(&self, name: &str) {
        self.find(name);
    }

    /// The numbers of `name`, whose type must be one of `types`.
    pub fn nums(&self, name: &str, types: &[&str]) -> Result<Option<&[f64]>> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        match &p.values {
            Values::Nums(v) if types.contains(&p.ty.as_str()) => Ok(Some(v)),
            _ => Err(self.error(p, format_args!("expected {}", types.join(" or ")))),
        }
    }

    /// A single float (or integer).
    pub fn float(&self, name: &str) -> Result<Option<f64>> {
        self.one(name, &["float", "integer"])
    }

    fn one(&self, name: &str, types: &[&str]) -> Result<Option<f64>> {
        match self.nums(name, types)? {
            None => Ok(None),
            Some([v]) => Ok(Some(*v)),
            Some(_) => Err(self.error(self.find(name).expect("found"), "expected one value")),
        }
    }

    pub fn int(&self, name: &str) -> Result<Option<i64>> {
        match self.one(name, &["integer"])? {
            Some(v) if v.fract() == 0.0 && v.abs() < 2f64.powi(53) => Ok(Some(v as i64)),
            Some(v) => Err(self.error(
                self.find(name).expect("found"),
                format_args!("{v} is not an integer"),
            )),
            None => Ok(None),
        }
    }

    /// Triples of a `point3`/`point`/`vector3`/`normal` list.
    pub fn triples(&self, name: &str, types: &[&str]) -> Result<Option<Vec<[f64; 3]>>> {
        let Some(v) = self.nums(name, types)? else {
            return Ok(None);
        };
        if v.len() % 3 != 0 {
            let p = self.find(name).expect("found");
            return Err(self.error(p, format_args!("{} values: not whole triples", v.len())));
        }
        Ok(Some(
            v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        ))
    }

    /// One point.
    pub fn point(&self, name: &str) -> Result<Option<[f64; 3]>> {
        match self.triples(name, &["point3", "point"])? {
            None => Ok(None),
            Some(v) if v.len() == 1 => Ok(Some(v[0])),
            Some(_) => Err(self.error(self.find(name).expect("found"), "expected one point")),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&str>> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        match &p.values {
            Values::Strs(v) if v.len() == 1 && matches!(p.ty.as_str(), "string" | "texture") => {
                Ok(Some(&v[0]))
            }
            _ => Err(self.error(p, "expected one string")),
        }
    }

    /// An RGB colour or a texture reference; spectra other than RGB are refused, since a
    /// wrong colour is a wrong image.
    pub fn color(&self, name: &str) -> Result<Option<Color>> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        match (p.ty.as_str(), &p.values) {
            ("rgb" | "color", Values::Nums(v)) if v.len() == 3 => {
                Ok(Some(Color::Rgb([v[0], v[1], v[2]])))
            }
            ("texture", Values::Strs(v)) if v.len() == 1 => Ok(Some(Color::Texture(v[0].clone()))),
            ("float", Values::Nums(v)) if v.len() == 1 => Ok(Some(Color::Rgb([v[0]; 3]))),
            ("spectrum" | "blackbody", _) => Err(self.error(
                p,
                "only \"rgb\" colours are supported (hairtrace renders in RGB)",
            )),
            _ => Err(self.error(p, "expected an rgb triple or a texture")),
        }
    }

    /// A float that may instead be a texture reference (Some(Err(name))).
    pub fn float_or_texture(&self, name: &str) -> Result<Option<std::result::Result<f64, String>>> {
        if let Some(p) = self
            .list
            .iter()
            .find(|p| p.name == name && p.ty == "texture")
        {
            p.used.set(true);
            if let Values::Strs(v) = &p.values {
                return Ok(Some(Err(v.join(" "))));
            }
        }
        Ok(self.float(name)?.map(Ok))
    }

    /// An error at this statement.
    pub fn fail(&self, message: impl std::fmt::Display) -> crate::Error {
        crate::Error::InvalidArg(format!("{}: {}: {message}", self.loc, self.what))
    }

    /// `e` placed at this statement, same kind.
    pub fn context(&self, e: crate::Error) -> crate::Error {
        e.context(format_args!("{}: {}", self.loc, self.what))
    }

    /// A warning at this statement.
    pub fn warning(&self, message: impl std::fmt::Display) -> Warning {
        (self.loc.clone(), format!("{}: {message}", self.what))
    }

    /// One warning for each parameter nobody read.
    pub fn unused(&self) -> Vec<Warning> {
        self.list
            .iter()
            .filter(|p| !p.used.get())
            .map(|p| {
                self.warning(format_args!(
                    "parameter \"{} {}\" is not supported and was ignored",
                    p.ty, p.name
                ))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(text: &str) -> Result<Params> {
        let mut lexer = Lexer::new(text, "t.pbrt");
        read_params(&mut lexer, "t.pbrt:1".into(), "Shape".into())
    }

    #[test]
    fn typed_lookups() {
        let p = params(
            "\"float fov\" 40 \"point3 P\" [0 1 2 3 4 5] \"rgb L\" [1 2 3] \
             \"string type\" \"flat\" \"bool b\" true \"texture reflectance\" \"wood\" Next",
        )
        .unwrap();
        assert_eq!(p.float("fov").unwrap(), Some(40.0));
        assert_eq!(
            p.triples("P", &["point3"]).unwrap(),
            Some(vec![[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])
        );
        assert_eq!(p.color("L").unwrap(), Some(Color::Rgb([1.0, 2.0, 3.0])));
        assert_eq!(p.string("type").unwrap(), Some("flat"));
        assert_eq!(
            p.color("reflectance").unwrap(),
            Some(Color::Texture("wood".into()))
        );
        assert_eq!(p.float("missing").unwrap(), None);
        assert_eq!(
            p.unused(),
            [(
                "t.pbrt:1".to_string(),
                "Shape: parameter \"bool b\" is not supported and was ignored".to_string()
            )]
        );
        assert!(
            p.float("P")
                .unwrap_err()
                .to_string()
                .contains("\"point3 P\": expected float")
        );
    }

    #[test]
    fn malformed_lists_are_errors() {
        for (text, message) in [
            ("\"float a\" [1 2", "t.pbrt:1: parameter \"a\": no `]`"),
            ("\"float a\" [1 \"x\"]", "parameter \"a\": mixed values"),
            ("\"float\" 1", "parameter \"float\": expected \"type name\""),
            ("\"float a\"", "parameter \"a\" has no value"),
            ("\"float a\" 1 \"float a\" 2", "parameter \"a\" given twice"),
        ] {
            let e = params(text).unwrap_err().to_string();
            assert!(e.contains(message), "{text}: {e}");
        }
        let p = params("\"spectrum L\" [300 1 800 1] \"point3 P\" [1 2]").unwrap();
        assert!(
            p.color("L")
                .unwrap_err()
                .to_string()
                .contains("only \"rgb\"")
        );
        assert!(
            p.triples("P", &["point3"])
                .unwrap_err()
                .to_string()
                .contains("not whole triples")
        );
    }
}
