//! A typed view of a spanned TOML tree: every accessor knows where its value came from, so
//! every error can point at it.

use crate::diagnostic::{Diagnostic, did_you_mean};

/// The largest magnitude of a number in a scene file: squares and products of numbers up to it
/// stay finite in f64, so nothing derived from the scene overflows to infinity or NaN.
pub const MAX_MAGNITUDE: f64 = 1e100;
use alhazen_math::Vec3;
use std::ops::Range;
use std::path::Path;
use toml::de::{DeTable, DeValue};

pub(crate) type R<T> = Result<T, Box<Diagnostic>>;

/// The file being read.
#[derive(Clone, Copy)]
pub(crate) struct Src<'s> {
    pub file: &'s Path,
    pub text: &'s str,
}

impl Src<'_> {
    pub fn error(&self, span: Range<usize>, msg: impl Into<String>) -> Box<Diagnostic> {
        Box::new(Diagnostic::at(self.file, self.text, span, msg))
    }
}

/// The parameters of the group instance being read: `"$name"` values stand for them.
pub(crate) type Scope<'a, 'i> = Option<std::rc::Rc<std::collections::HashMap<String, Node<'a, 'i>>>>;

/// A value with its span.
#[derive(Clone)]
pub(crate) struct Node<'a, 'i> {
    pub src: Src<'a>,
    pub v: &'a DeValue<'i>,
    pub span: Range<usize>,
    /// The key this value was found under, for messages.
    pub key: &'a str,
    /// Group parameters in force where the value was found.
    pub scope: Scope<'a, 'i>,
}

impl<'a, 'i> Node<'a, 'i> {
    /// The node itself, or the parameter value a `"$name"` string stands for in `scope`.
    pub fn resolved(self) -> Self {
        let Some(name) = self.v.as_str().and_then(|s| s.strip_prefix('$')) else { return self };
        match self.scope.as_ref().and_then(|sc| sc.get(name)) {
            Some(value) => Node { key: self.key, ..value.clone() },
            None => self,
        }
    }
}

fn kind(v: &DeValue<'_>) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a date",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

impl<'a, 'i> Node<'a, 'i> {
    pub fn err(&self, msg: impl Into<String>) -> Box<Diagnostic> {
        self.src.error(self.span.clone(), msg)
    }

    fn expected(&self, what: &str) -> Box<Diagnostic> {
        if let Some(p) = self.v.as_str().filter(|s| s.starts_with('$')) {
            let known = self.scope.as_ref().map(|sc| {
                let mut k: Vec<String> = sc.keys().map(|k| format!("${k}")).collect();
                k.sort();
                k.join(", ")
            });
            return self.err(format!(
                "`{}`: parameter `{p}` has no value here (a group's parameters: {})",
                self.key,
                known.filter(|k| !k.is_empty()).unwrap_or_else(|| "none: this is not inside a group".into())
            ));
        }
        self.err(format!("`{}`: expected {what}, found {}", self.key, kind(self.v)))
    }

    pub fn f64(&self) -> R<f64> {
        let parsed = match self.v {
            DeValue::Integer(i) => {
                let digits = i.as_str().replace('_', "");
                i64::from_str_radix(&digits, i.radix()).map(|x| x as f64).ok()
            }
            DeValue::Float(x) => x.as_str().replace('_', "").parse::<f64>().ok(),
            _ => return Err(self.expected("a number")),
        };
        match parsed {
            Some(x) if x.abs() <= MAX_MAGNITUDE => Ok(x),
            Some(x) if x.is_finite() => Err(self.err(format!(
                "`{}`: {x:e} is beyond ±1e100, the largest magnitude alhazen computes with (its squares and products would overflow)",
                self.key
            ))),
            _ => Err(self.err(format!("`{}`: expected a finite number", self.key))),
        }
    }

    pub fn positive(&self) -> R<f64> {
        let x = self.f64()?;
        if x > 0.0 { Ok(x) } else { Err(self.err(format!("`{}` must be positive, found {x}", self.key))) }
    }

    pub fn non_negative(&self) -> R<f64> {
        let x = self.f64()?;
        if x >= 0.0 { Ok(x) } else { Err(self.err(format!("`{}` must be ≥ 0, found {x}", self.key))) }
    }

    pub fn in_range(&self, lo: f64, hi: f64) -> R<f64> {
        let x = self.f64()?;
        if (lo..=hi).contains(&x) {
            Ok(x)
        } else {
            Err(self.err(format!("`{}` must lie in [{lo}, {hi}], found {x}", self.key)))
        }
    }

    pub fn integer(&self, lo: u64, hi: u64) -> R<u64> {
        let DeValue::Integer(i) = self.v else { return Err(self.expected("an integer")) };
        let digits = i.as_str().replace('_', "");
        match i64::from_str_radix(&digits, i.radix()) {
            Ok(x) if x >= 0 && (lo..=hi).contains(&(x as u64)) => Ok(x as u64),
            _ => Err(self.err(format!("`{}` must be an integer in {lo}..={hi}, found {}", self.key, i.as_str()))),
        }
    }

    pub fn bool(&self) -> R<bool> {
        self.v.as_bool().ok_or_else(|| self.expected("true or false"))
    }

    pub fn str(&self) -> R<&'a str> {
        self.v.as_str().ok_or_else(|| self.expected("a string"))
    }

    /// One of `choices`, with a suggestion for near misses.
    pub fn choice<'c>(&self, choices: &[&'c str]) -> R<&'c str> {
        let s = self.str()?;
        if let Some(c) = choices.iter().find(|c| **c == s) {
            return Ok(c);
        }
        let list = choices.iter().map(|c| format!("\"{c}\"")).collect::<Vec<_>>().join(", ");
        let mut d = self.err(format!("`{}`: unknown value \"{s}\", expected one of {list}", self.key));
        if let Some(m) = did_you_mean(s, choices.iter().copied()) {
            *d = d.with_help(format!("did you mean \"{m}\"?"));
        }
        Err(d)
    }

    pub fn array(&self) -> R<Vec<Node<'a, 'i>>> {
        let DeValue::Array(items) = self.v else { return Err(self.expected("an array")) };
        Ok(items
            .iter()
            .map(|item| {
                Node { src: self.src, v: item.get_ref(), span: item.span(), key: self.key, scope: self.scope.clone() }
                    .resolved()
            })
            .collect())
    }

    pub fn numbers<const N: usize>(&self) -> R<[f64; N]> {
        let items = self.array().map_err(|_| self.expected(&format!("an array of {N} numbers")))?;
        if items.len() != N {
            return Err(self.err(format!("`{}`: expected {N} numbers, found {}", self.key, items.len())));
        }
        let mut out = [0.0; N];
        for (o, item) in out.iter_mut().zip(&items) {
            *o = item.f64()?;
        }
        Ok(out)
    }

    pub fn vec3(&self) -> R<Vec3> {
        self.numbers::<3>().map(Vec3::from_array)
    }

    /// A direction, normalised; one already of unit length (to rounding) is kept as written, so
    /// a scene written back by `write` reads to the same bits.
    pub fn unit_vec3(&self) -> R<Vec3> {
        let v = self.vec3()?;
        if (v.length_squared() - 1.0).abs() <= 4.0 * f64::EPSILON {
            return Ok(v);
        }
        v.try_normalize().ok_or_else(|| self.err(format!("`{}` must be a non-zero vector", self.key)))
    }

    /// A colour: one number (grey), `[r, g, b]` (each ≥ 0), `{ hsv = [h, s, v] }` or
    /// `{ hsl = [h, s, l] }` (hue in degrees, the others in `[0, 1]`; the course's colour models).
    pub fn rgb(&self) -> R<Vec3> {
        let c = match self.v {
            DeValue::Integer(_) | DeValue::Float(_) => Vec3::splat(self.f64()?),
            DeValue::Array(_) => self.vec3()?,
            DeValue::Table(_) => self.hue_model()?,
            _ => {
                return Err(self.expected("a colour (a number, [r, g, b], { hsv = [h, s, v] } or { hsl = [h, s, l] })"));
            }
        };
        if c.min_element() < 0.0 {
            return Err(self.err(format!("`{}`: colour components must be ≥ 0", self.key)));
        }
        Ok(c)
    }

    /// `{ hsv = [h, s, v] }` or `{ hsl = [h, s, l] }` as RGB.
    fn hue_model(&self) -> R<Vec3> {
        let t = self.table(&["hsv", "hsl"])?;
        let (n, hsv) = match (t.get("hsv"), t.get("hsl")) {
            (Some(n), None) => (n, true),
            (None, Some(n)) => (n, false),
            _ => return Err(self.err(format!("`{}`: a colour table has one key, `hsv` or `hsl`", self.key))),
        };
        let [h, s, x] = n.numbers::<3>()?;
        if !h.is_finite() || !(0.0..=1.0).contains(&s) || !(0.0..=1.0).contains(&x) {
            let what =
                if hsv { "[hue in degrees, saturation, value]" } else { "[hue in degrees, saturation, lightness]" };
            return Err(n.err(format!("`{}`: expected {what}, saturation and the last within [0, 1]", n.key)));
        }
        Ok(if hsv { alhazen_math::color::hsv_to_rgb(h, s, x) } else { alhazen_math::color::hsl_to_rgb(h, s, x) })
    }

    pub fn table(&self, keys: &[&str]) -> R<Table<'a, 'i>> {
        let DeValue::Table(t) = self.v else { return Err(self.expected("a table")) };
        let table = Table { src: self.src, t, span: self.span.clone(), name: self.key, scope: self.scope.clone() };
        table.check_keys(keys)?;
        Ok(table)
    }

    pub fn is_table(&self) -> bool {
        matches!(self.v, DeValue::Table(_))
    }

    pub fn is_array(&self) -> bool {
        matches!(self.v, DeValue::Array(_))
    }
}

/// A table with its span and the name it is known by in messages.
#[derive(Clone)]
pub(crate) struct Table<'a, 'i> {
    pub src: Src<'a>,
    pub t: &'a DeTable<'i>,
    pub span: Range<usize>,
    pub name: &'a str,
    /// Group parameters in force.
    pub scope: Scope<'a, 'i>,
}

impl<'a, 'i> Table<'a, 'i> {
    pub fn get(&self, key: &str) -> Option<Node<'a, 'i>> {
        self.t.iter().find(|(k, _)| k.get_ref().as_ref() == key).map(|(k, v)| {
            Node { src: self.src, v: v.get_ref(), span: v.span(), key: k.get_ref().as_ref(), scope: self.scope.clone() }
                .resolved()
        })
    }

    pub fn req(&self, key: &str) -> R<Node<'a, 'i>> {
        self.get(key).ok_or_else(|| {
            self.src.error(self.header_span(), format!("`{}` is missing the required key `{key}`", self.name))
        })
    }

    /// The start of the table for messages about the whole table.
    fn header_span(&self) -> Range<usize> {
        let start = self.span.start;
        start..start + 1
    }

    pub fn keys(&self) -> impl Iterator<Item = (&'a str, Range<usize>)> + '_ {
        self.t.iter().map(|(k, _)| (k.get_ref().as_ref(), k.span()))
    }

    pub fn check_keys(&self, known: &[&str]) -> R<()> {
        for (k, span) in self.keys() {
            if !known.contains(&k) {
                let list = known.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", ");
                let mut d =
                    self.src.error(span, format!("unknown key `{k}` in `{}`; expected one of {list}", self.name));
                if let Some(m) = did_you_mean(k, known.iter().copied()) {
                    *d = d.with_help(format!("did you mean `{m}`?"));
                } else if crate::parse::TOP_KEYS.contains(&k) {
                    *d = d.with_help(format!(
                        "`{k}` is a top-level key: in TOML it must come before the first [table] header"
                    ));
                }
                return Err(d);
            }
        }
        Ok(())
    }

    pub fn opt_f64(&self, key: &str, default: f64) -> R<f64> {
        self.get(key).map_or(Ok(default), |n| n.f64())
    }

    pub fn opt_rgb(&self, key: &str, default: Vec3) -> R<Vec3> {
        self.get(key).map_or(Ok(default), |n| n.rgb())
    }

    pub fn opt_positive(&self, key: &str, default: f64) -> R<f64> {
        self.get(key).map_or(Ok(default), |n| n.positive())
    }

    pub fn opt_bool(&self, key: &str, default: bool) -> R<bool> {
        self.get(key).map_or(Ok(default), |n| n.bool())
    }

    pub fn opt_vec3(&self, key: &str, default: Vec3) -> R<Vec3> {
        self.get(key).map_or(Ok(default), |n| n.vec3())
    }
}
