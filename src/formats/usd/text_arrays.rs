//! A fast path for the numeric arrays of a text (.usda) layer. openusd's text parser reads
//! an array one token at a time, which is most of a large groom's read time. [`lift`] cuts
//! every numeric array authored as an attribute's default out of the text, leaving a
//! one-element placeholder that holds its index; openusd parses the rest; [`restore`]
//! reads each array under a strict grammar (a part of what openusd accepts) with the
//! number conversions openusd uses (`FromStr` on each number's text) and puts it where its
//! placeholder is.
//!
//! A numeric array anywhere else (metadata, a dictionary, time samples, a variant) makes
//! [`lift`] leave the whole layer to openusd; an array outside the grammar (`inf`, `nan`, a
//! comment or a trailing comma inside it) or a placeholder [`restore`] cannot account for
//! makes the caller read the file again without the fast path: what openusd accepts,
//! refuses or reports stays as it was. One exception: a tuple with too few or too many
//! numbers for its type is an error here, where openusd 0.6 reads it without a word and
//! fills in what is missing.

use std::str::FromStr;

use openusd::gf;
use openusd::sdf::{Layer, Path, SpecType, Value};

use crate::Error;
use crate::error::invalid_arg;

/// A text layer's numeric arrays, cut out of it by [`lift`].
pub(super) struct TextArrays {
    text: Vec<u8>,
    arrays: Vec<Array>,
}

/// One array: the attribute it is the default of, where its text is and its shape.
struct Array {
    name: String,
    /// The text after the opening bracket, the closing one included.
    span: std::ops::Range<usize>,
    /// Numbers per element, as its first element has them: 1 for a number, else the
    /// size of the tuple.
    arity: usize,
}

/// What openusd's lexer skips as white space.
const SPACE: &[u8] = b" \t\r\n\x0c";

/// The layer's text with each numeric attribute default replaced by a placeholder, and
/// the arrays cut out; the text back when the layer must go to openusd untouched.
pub(super) fn lift(text: Vec<u8>) -> Result<(Vec<u8>, TextArrays), Vec<u8>> {
    match cut(&text) {
        Some((out, arrays)) => Ok((out, TextArrays { text, arrays })),
        None => Err(text),
    }
}

/// [`lift`]'s work: the new text and the arrays, or `None`.
fn cut(text: &[u8]) -> Option<(Vec<u8>, Vec<Array>)> {
    let mut out = Vec::with_capacity(text.len() / 4);
    let mut arrays = Vec::new();
    // Open blocks: `true` for a prim's body, `false` for metadata (`(`), a dictionary,
    // time samples or a variant set (`= {`) and all they hold.
    let mut blocks: Vec<bool> = Vec::new();
    let (mut i, mut copied) = (0, 0);
    while i < text.len() {
        let c = text[i];
        match c {
            b'"' | b'\'' => i = skip_string(text, i)?,
            b'<' => i = find(text, i + 1, b">")? + 1,
            b'@' if text[i..].starts_with(b"@@@") => i = find(text, i + 3, b"@@@")? + 3,
            b'@' => i = find(text, i + 1, b"@")? + 1,
            b'#' => i = find_any(text, i, b"\r\n"),
            b'/' if text.get(i + 1) == Some(&b'*') => i = find(text, i + 2, b"*/")? + 2,
            b'{' => {
                blocks.push(before(text, i) != Some(b'='));
                i += 1;
            }
            b'(' => {
                blocks.push(false);
                i += 1;
            }
            b'}' | b')' => {
                blocks.pop()?;
                i += 1;
            }
            b'[' => {
                let in_body = blocks.iter().all(|&b| b);
                match attribute_default(text, i).filter(|_| in_body) {
                    Some(name) if starts_number(text, i) => {
                        // The array is checked as it is converted, in `restore`.
                        let end = find(text, i, b"]")? + 1;
                        let arity = first_arity(&text[i + 1..end]);
                        out.extend_from_slice(&text[copied..i]);
                        placeholder(&mut out, arrays.len(), arity);
                        arrays.push(Array {
                            name,
                            span: i + 1..end,
                            arity,
                        });
                        (i, copied) = (end, end);
                    }
                    _ => i = list_end(text, i)?,
                }
            }
            _ => i += 1,
        }
    }
    if !blocks.is_empty() || arrays.is_empty() {
        return None;
    }
    out.extend_from_slice(&text[copied..]);
    Some((out, arrays))
}

/// Puts the arrays back into `layer` (parsed from [`lift`]'s text), each where its
/// placeholder is. `Ok(None)`, the layer unchanged, when a placeholder is missing, found
/// twice or on another attribute, or an array is outside the grammar or of a kind not read
/// here; an error naming the attribute for a tuple with too few or too many numbers.
pub(super) fn restore(layer: &mut Layer, arrays: &TextArrays) -> Result<Option<()>, Error> {
    let mut found: Vec<Option<Path>> = vec![None; arrays.arrays.len()];
    let data = layer.data();
    for path in data.spec_paths() {
        if data.spec_type(&path) != Some(SpecType::Attribute) {
            continue;
        }
        let Ok(Some(v)) = data.try_field(&path, "default") else {
            continue;
        };
        let Some(k) = placeholder_index(&v) else {
            continue;
        };
        let Some(a) = arrays.arrays.get(k) else {
            return Ok(None);
        };
        let slot = &mut found[k];
        let property = path.as_str().rsplit_once('.').map(|(_, name)| name);
        if slot.is_some() || property != Some(a.name.as_str()) {
            return Ok(None);
        }
        *slot = Some(path);
    }
    let Some(paths) = found.into_iter().collect::<Option<Vec<Path>>>() else {
        return Ok(None);
    };
    let mut values = Vec::with_capacity(paths.len());
    for (path, a) in paths.into_iter().zip(&arrays.arrays) {
        let Ok(Some(like)) = data.try_field(&path, "default") else {
            return Ok(None);
        };
        match arrays.convert(a, &like) {
            Ok(Some(value)) => values.push((value, path)),
            Ok(None) => return Ok(None),
            Err(element) => {
                return Err(invalid_arg!(
                    "{}: element {element} is a tuple of another size than the \
                     attribute's type holds",
                    path.as_str()
                ));
            }
        }
    }
    let put = layer.edit(|edit| {
        for (value, path) in values {
            edit.data_mut().set_field(&path, "default", value);
        }
        Ok(())
    });
    Ok(put.ok().map(|_| ()))
}

impl TextArrays {
    /// Array `a` as the same kind of value as its placeholder `like`, if its text keeps to
    /// the grammar. `Err(element)` for a tuple whose count of numbers is not its type's.
    fn convert(&self, a: &Array, like: &Value) -> Result<Option<Value>, usize> {
        // The grammar admits ASCII only: anything else is refused below.
        let Ok(text) = std::str::from_utf8(&self.text[a.span.clone()]) else {
            return Ok(None);
        };
        let arity = match like {
            Value::Vec2fVec(_) | Value::Vec2dVec(_) => 2,
            Value::Vec3fVec(_) | Value::Vec3dVec(_) => 3,
            Value::Vec4fVec(_) | Value::Vec4dVec(_) => 4,
            _ => 1,
        };
        if (arity == 1) != (a.arity == 1) {
            return Ok(None);
        }
        if arity != a.arity {
            return Err(0);
        }
        Ok(match like {
            Value::IntVec(_) => scalars(text).map(Value::IntVec),
            Value::FloatVec(_) => scalars(text).map(Value::FloatVec),
            Value::DoubleVec(_) => scalars(text).map(Value::DoubleVec),
            Value::Vec2fVec(_) => tuples::<f32, gf::Vec2f, 2>(text)?.map(Value::Vec2fVec),
            Value::Vec3fVec(_) => tuples::<f32, gf::Vec3f, 3>(text)?.map(Value::Vec3fVec),
            Value::Vec4fVec(_) => tuples::<f32, gf::Vec4f, 4>(text)?.map(Value::Vec4fVec),
            Value::Vec2dVec(_) => tuples::<f64, gf::Vec2d, 2>(text)?.map(Value::Vec2dVec),
            Value::Vec3dVec(_) => tuples::<f64, gf::Vec3d, 3>(text)?.map(Value::Vec3dVec),
            Value::Vec4dVec(_) => tuples::<f64, gf::Vec4d, 4>(text)?.map(Value::Vec4dVec),
            _ => None,
        })
    }
}

/// The index a placeholder holds, if `v` is a one-element array of a kind [`restore`]
/// converts whose first number is a whole number.
fn placeholder_index(v: &Value) -> Option<usize> {
    let first: f64 = match v {
        Value::IntVec(x) if x.len() == 1 => f64::from(x[0]),
        Value::FloatVec(x) if x.len() == 1 => f64::from(x[0]),
        Value::DoubleVec(x) if x.len() == 1 => x[0],
        Value::Vec2fVec(x) if x.len() == 1 => f64::from(<[f32; 2]>::from(x[0])[0]),
        Value::Vec3fVec(x) if x.len() == 1 => f64::from(<[f32; 3]>::from(x[0])[0]),
        Value::Vec4fVec(x) if x.len() == 1 => f64::from(<[f32; 4]>::from(x[0])[0]),
        Value::Vec2dVec(x) if x.len() == 1 => <[f64; 2]>::from(x[0])[0],
        Value::Vec3dVec(x) if x.len() == 1 => <[f64; 3]>::from(x[0])[0],
        Value::Vec4dVec(x) if x.len() == 1 => <[f64; 4]>::from(x[0])[0],
        _ => return None,
    };
    (first >= 0.0 && first.fract() == 0.0 && first < usize::MAX as f64).then_some(first as usize)
}

/// An array's text after its opening bracket, read under the grammar: numbers, or
/// tuples of numbers, separated by commas, spaces anywhere between, then `]`.
struct Reader<'a> {
    text: &'a str,
    at: usize,
}

impl<'a> Reader<'a> {
    fn new(text: &'a str) -> Self {
        Self { text, at: 0 }
    }

    /// Consumes `c` after any spaces, if it is there.
    fn punct(&mut self, c: u8) -> bool {
        self.at = skip_space(self.text.as_bytes(), self.at);
        let found = self.text.as_bytes().get(self.at) == Some(&c);
        self.at += usize::from(found);
        found
    }

    /// Consumes `]` and whether the text ends there; else a comma must follow.
    fn next_element(&mut self) -> Option<bool> {
        if self.punct(b']') {
            return (self.at == self.text.len()).then_some(false);
        }
        self.punct(b',').then_some(true)
    }

    /// The next number, converted as openusd converts its token.
    fn number<T: FromStr>(&mut self) -> Option<T> {
        let start = skip_space(self.text.as_bytes(), self.at);
        self.at = number(self.text.as_bytes(), start)?;
        self.text[start..self.at].parse().ok()
    }
}

/// A typical number's text with its separator: what an array's length is guessed from.
const BYTES_PER_NUMBER: usize = 12;

fn scalars<T: FromStr>(text: &str) -> Option<Vec<T>> {
    let mut out = Vec::with_capacity(text.len() / BYTES_PER_NUMBER);
    let mut r = Reader::new(text);
    loop {
        out.push(r.number()?);
        if !r.next_element()? {
            return Some(out);
        }
    }
}

/// Tuples of `N` numbers. `Err(element)` for an element with another count of numbers,
/// which openusd would read without a word (it fills the missing numbers); `Ok(None)` for
/// text outside the grammar.
fn tuples<E: FromStr + Copy + Default, T: From<[E; N]>, const N: usize>(
    text: &str,
) -> Result<Option<Vec<T>>, usize> {
    let mut out = Vec::with_capacity(text.len() / (N * BYTES_PER_NUMBER));
    let mut r = Reader::new(text);
    loop {
        if !r.punct(b'(') {
            return Ok(None);
        }
        let mut e = [E::default(); N];
        let mut count = 0;
        loop {
            let Some(x) = r.number() else {
                return Ok(None);
            };
            if let Some(slot) = e.get_mut(count) {
                *slot = x;
            }
            count += 1;
            if r.punct(b')') {
                break;
            }
            if !r.punct(b',') {
                return Ok(None);
            }
        }
        if count != N {
            return Err(out.len());
        }
        out.push(T::from(e));
        match r.next_element() {
            Some(true) => {}
            Some(false) => return Ok(Some(out)),
            None => return Ok(None),
        }
    }
}

/// How many numbers the first element of an array's text holds: 1 unless it is a tuple,
/// else its commas plus one (the tuple itself is checked when it is read).
fn first_arity(text: &[u8]) -> usize {
    let at = skip_space(text, 0);
    if text.get(at) != Some(&b'(') {
        return 1;
    }
    let end = find(text, at, b")").unwrap_or(text.len());
    1 + text[at..end].iter().filter(|&&c| c == b',').count()
}

/// Writes array `k`'s placeholder: `[k]`, or `[(k, 0, ...)]` for tuples.
fn placeholder(out: &mut Vec<u8>, k: usize, arity: usize) {
    let k = k.to_string();
    out.push(b'[');
    if arity == 1 {
        out.extend_from_slice(k.as_bytes());
    } else {
        out.push(b'(');
        out.extend_from_slice(k.as_bytes());
        out.extend(std::iter::repeat_n(b", 0".iter().copied(), arity - 1).flatten());
        out.push(b')');
    }
    out.push(b']');
}

/// The attribute's name when the `[` at `i` opens its default: `TYPE[] NAME = [`.
fn attribute_default(text: &[u8], i: usize) -> Option<String> {
    let eq = last_non_space(text, i)?;
    (text[eq] == b'=').then_some(())?;
    let name_end = last_non_space(text, eq)? + 1;
    let mut start = name_end;
    while start > 0 && is_name_byte(text[start - 1]) {
        start -= 1;
    }
    let brackets = last_non_space(text, start)?;
    let ok = start < name_end
        && text[start].is_ascii_alphabetic()
        && brackets >= 1
        && &text[brackets - 1..=brackets] == b"[]"
        && brackets >= 2
        && is_name_byte(text[brackets - 2]);
    ok.then(|| String::from_utf8_lossy(&text[start..name_end]).into_owned())
}

fn is_name_byte(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b':'
}

/// The end of the number at `i`, one openusd's lexer reads as a whole number token:
/// an optional sign, digits, optionally a dot and digits, optionally an exponent. What
/// follows must end it (space or punctuation), so the lexer cannot read it otherwise.
fn number(text: &[u8], i: usize) -> Option<usize> {
    let digits = |from: usize| {
        let mut at = from;
        while text.get(at).is_some_and(u8::is_ascii_digit) {
            at += 1;
        }
        (at > from).then_some(at)
    };
    let mut at = i + usize::from(matches!(text.get(i), Some(b'+' | b'-')));
    at = digits(at)?;
    if text.get(at) == Some(&b'.') {
        at = digits(at + 1)?;
    }
    if matches!(text.get(at), Some(b'e' | b'E')) {
        at += 1 + usize::from(matches!(text.get(at + 1), Some(b'+' | b'-')));
        at = digits(at)?;
    }
    matches!(
        text.get(at)?,
        b' ' | b'\t' | b'\r' | b'\n' | b'\x0c' | b',' | b')' | b']'
    )
    .then_some(at)
}

/// Whether the list at `i` starts with a number or a tuple: it holds no strings, paths
/// nor asset paths (a list of those is read by openusd), and is not empty.
fn starts_number(text: &[u8], i: usize) -> bool {
    text.get(skip_space(text, i + 1))
        .is_some_and(|c| c.is_ascii_digit() || b"+-.(".contains(c))
}

/// The end of a list that is not a numeric attribute default: it may hold strings,
/// paths and asset paths only (a type's `[]`, targets, tokens), else `None`.
fn list_end(text: &[u8], i: usize) -> Option<usize> {
    let mut at = i + 1;
    loop {
        at = skip_space(text, at);
        match *text.get(at)? {
            b']' => return Some(at + 1),
            b',' => at += 1,
            b'"' | b'\'' => at = skip_string(text, at)?,
            b'<' => at = find(text, at + 1, b">")? + 1,
            b'@' if text[at..].starts_with(b"@@@") => at = find(text, at + 3, b"@@@")? + 3,
            b'@' => at = find(text, at + 1, b"@")? + 1,
            _ => return None,
        }
    }
}

/// The end of the string at `i` (single, double or triple quoted, backslash escapes in
/// the single-line forms).
fn skip_string(text: &[u8], i: usize) -> Option<usize> {
    let q = text[i];
    let triple = [q, q, q];
    if text[i..].starts_with(&triple) {
        return Some(find(text, i + 3, &triple)? + 3);
    }
    let mut at = i + 1;
    loop {
        match *text.get(at)? {
            b'\\' => at += 2,
            c if c == q => return Some(at + 1),
            _ => at += 1,
        }
    }
}

fn find(text: &[u8], from: usize, what: &[u8]) -> Option<usize> {
    let rest = text.get(from..)?;
    let at = match what {
        [c] => rest.iter().position(|b| b == c),
        _ => rest.windows(what.len()).position(|w| w == what),
    };
    at.map(|p| from + p)
}

fn find_any(text: &[u8], from: usize, any: &[u8]) -> usize {
    text[from..]
        .iter()
        .position(|c| any.contains(c))
        .map_or(text.len(), |p| from + p)
}

fn skip_space(text: &[u8], from: usize) -> usize {
    from + text
        .get(from..)
        .map_or(0, |t| t.iter().take_while(|c| SPACE.contains(c)).count())
}

/// The index of the last byte before `i` that is not a space.
fn last_non_space(text: &[u8], i: usize) -> Option<usize> {
    text[..i].iter().rposition(|c| !SPACE.contains(c))
}

/// The last byte before `i` that is not a space.
fn before(text: &[u8], i: usize) -> Option<u8> {
    last_non_space(text, i).map(|j| text[j])
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::super::{Prims, open, read_lifting, read_stage, read_usd_file, resolver};
    use super::*;

    fn lifted(text: &str) -> String {
        let (out, _) = lift(text.as_bytes().to_vec()).unwrap_or_else(|_| panic!("{text}"));
        String::from_utf8(out).unwrap()
    }

    /// The reader without the fast path, as `read_usd_file` reports it.
    fn read_plain(path: &Path) -> String {
        let name = path.to_str().unwrap();
        let bytes = std::fs::metadata(path).unwrap().len();
        let read = open(name, resolver::CheckingResolver::default())
            .and_then(|stage| read_stage(&stage, bytes, None, Prims::Curves))
            .map_err(|e| e.context(path.display()));
        format!("{read:?}")
    }

    #[test]
    fn lift_cuts_numeric_defaults_and_leaves_the_rest() {
        let text = "#usda 1.0 [1]\n( doc = \"\"\"a [2] \"\"\" )\ndef X \"a\" ( apiSchemas = [\"B\"] )\n{\n    \
                    int[] n = [4, -5] # [3]\n    uniform point3f[] p = [ (0, 1e-3, +2.5),\n(3, 4, 5) ] (\n        \
                    interpolation = \"vertex\"\n    )\n    float[] e = []\n    token[] t = [\"x\", 'y']\n    \
                    rel r = [</a>, </b>]\n    asset[] s = [@f@]\n    /* [6] */ double2[] d = [(1, 2)]\n}\n";
        let want = "#usda 1.0 [1]\n( doc = \"\"\"a [2] \"\"\" )\ndef X \"a\" ( apiSchemas = [\"B\"] )\n{\n    \
                    int[] n = [0] # [3]\n    uniform point3f[] p = [(1, 0, 0)] (\n        \
                    interpolation = \"vertex\"\n    )\n    float[] e = []\n    token[] t = [\"x\", 'y']\n    \
                    rel r = [</a>, </b>]\n    asset[] s = [@f@]\n    /* [6] */ double2[] d = [(2, 0)]\n}\n";
        assert_eq!(lifted(text), want);
    }

    #[test]
    fn lift_leaves_alone_a_layer_it_cannot_account_for() {
        let prim =
            |body: &str| format!("#usda 1.0\ndef X \"a\"\n{{\n    int[] n = [4]\n{body}\n}}\n");
        let cases = [
            prim("    float[] w.timeSamples = { 0: [1, 2] }"),
            prim("    float x = 1 ( customData = { int[] k = [1] } )"),
            prim("    variantSet \"v\" = { \"a\" { float[] w = [1] } }"),
            prim("    matrix4d[] m = [( (1, 0), (0, 1) )]").replace("[( (", "[ [( ("),
            prim("    float[] w = [inf, 1]\n    float[] u = [1 2]").replace("[4]", "[nan]"),
            prim("    }"),
            "#usda 1.0\ndef X \"a\"\n{\n    float[] w = [1]\n".to_string(),
            "#usda 1.0\ndef X \"a\"\n{\n    string s = \"open\n}\n".to_string(),
            "#usda 1.0\n".to_string(),
        ];
        for text in cases {
            let back = lift(text.as_bytes().to_vec()).err();
            assert_eq!(back.as_deref(), Some(text.as_bytes()), "{text}");
        }
    }

    fn fixtures() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/usd")
    }

    /// Every text fixture goes through the fast path, and reads to the same grooms, bit for
    /// bit, as openusd reads it.
    #[test]
    fn text_fixtures_read_through_the_fast_path_as_openusd_reads_them() {
        let mut names: Vec<PathBuf> = std::fs::read_dir(fixtures())
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "usda"))
            .collect();
        names.sort();
        assert!(names.len() >= 12, "{names:?}");
        for path in names {
            let text = std::fs::read(&path).unwrap();
            assert!(lift(text).is_ok(), "{}", path.display());
            let bytes = std::fs::metadata(&path).unwrap().len();
            let fast = read_lifting(path.to_str().unwrap(), bytes, None, Prims::Curves)
                .unwrap()
                .unwrap_or_else(|| panic!("{}: the fast path gave up", path.display()));
            assert_eq!(
                format!("{:?}", Ok::<_, crate::Error>(fast)),
                read_plain(&path)
            );
        }
    }

    /// Arrays the grammar does not admit give openusd's own result: its error where it
    /// refuses them, its value where it reads them. (Tuples of the wrong size are refused
    /// here instead: tests/pipeline/usd.rs.)
    #[test]
    fn arrays_outside_the_grammar_read_as_openusd_reads_them() {
        let ok = "int[] curveVertexCounts = [4]\n    point3f[] points = [(0,0,0),(0,1,0),(0,2,0),(0,3,0)]\n    \
                  float[] widths = [0.1] (interpolation = \"constant\")\n    uniform token type = \"linear\"";
        let cases = [
            ("(0,3,0)]", "(0,3,0x)]"),
            ("(0,3,0)]", "(0,3,0)"),
            ("[4]", "[4.5]"),
            ("[4]", "[1e1]"),
            ("[4]", "[4,]"),
            ("[4]", "[4 ]"),
            ("[4]", "[+4]"),
            ("[4]", "[4"),
            ("[0.1]", "[.1]"),
            ("[0.1]", "[0.1; ]"),
            ("[0.1]", "[0.1e]"),
            ("[0.1]", "[inf]"),
            ("[0.1]", "[1e99]"),
            ("(0,3,0)]", "(0,3,0)]]"),
            ("(0,0,0),", "(0,0,0) ,"),
            ("(0,0,0),", "(0,0,0)"),
            ("(0,0,0),", "(0,0,0),,"),
            ("(0,0,0),", "(0,\"0\",0),"),
        ];
        let dir =
            std::env::temp_dir().join(format!("hairtrace-text-arrays-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (i, (from, to)) in cases.iter().enumerate() {
            let path = dir.join(format!("case{i}.usda"));
            let body = ok.replacen(from, to, 1);
            std::fs::write(
                &path,
                format!("#usda 1.0\ndef BasisCurves \"c\"\n{{\n    {body}\n}}\n"),
            )
            .unwrap();
            let got = format!("{:?}", read_usd_file(&path));
            assert_eq!(got, read_plain(&path), "{to}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
