//! Scenes from Python: a dict (in serde's JSON shape: a struct is a dict of its fields, an enum
//! variant a one-key dict `{"Variant": content}` or, without content, the string `"Variant"`,
//! tuples and vectors are lists) is written as the RON text of the same scene, guided by the
//! scene's own types, so the render reads exactly what a scene file would give it.

use super::{error, error_msg};
use crate::description::schema::SceneFile;
use pyo3::prelude::*;
use serde::de::{self, DeserializeSeed, IntoDeserializer, Visitor};
use serde::Deserialize;
use serde_json::Value;
use std::fmt::{self, Write as _};

/// An error of a dict scene, at a field path (`objects[2].shape.Sphere.radius`).
#[derive(Debug)]
struct DictError {
    path: Option<String>,
    message: String,
}

impl fmt::Display for DictError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(p) if !p.is_empty() => write!(f, "{p}: {}", self.message),
            _ => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for DictError {}

impl de::Error for DictError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        DictError {
            path: None,
            message: msg.to_string(),
        }
    }
}

impl DictError {
    /// The innermost path wins: it is attached first.
    fn at(mut self, path: &str) -> Self {
        if self.path.is_none() {
            self.path = Some(path.to_string());
        }
        self
    }
}

type R<T> = Result<T, DictError>;

/// The content of a variant given without one.
static NULL: Value = Value::Null;

/// A value of the dict being read as type `T`, writing `T`'s RON text to `out`.
struct Ron<'a> {
    v: &'a Value,
    out: &'a mut String,
    path: String,
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

fn quoted(s: &str) -> String {
    // A JSON string literal is a valid RON string literal with the same value.
    serde_json::to_string(s).expect("a string serialises")
}

impl<'a> Ron<'a> {
    fn child(&mut self, v: &'a Value, segment: &str) -> Ron<'_> {
        let path = if segment.starts_with('[') || self.path.is_empty() {
            format!("{}{segment}", self.path)
        } else {
            format!("{}.{segment}", self.path)
        };
        Ron {
            v,
            out: &mut *self.out,
            path,
        }
    }

    fn kind(&self) -> &'static str {
        match self.v {
            Value::Null => "None",
            Value::Bool(_) => "a bool",
            Value::Number(_) => "a number",
            Value::String(_) => "a string",
            Value::Array(_) => "a list",
            Value::Object(_) => "a dict",
        }
    }

    fn expected(&self, what: &str) -> DictError {
        DictError {
            path: Some(self.path.clone()),
            message: format!("expected {what}, found {}", self.kind()),
        }
    }

    fn list(&self, what: &str) -> R<&'a Vec<Value>> {
        match self.v {
            Value::Array(a) => Ok(a),
            _ => Err(self.expected(what)),
        }
    }

    fn dict(&self, what: &str) -> R<&'a serde_json::Map<String, Value>> {
        match self.v {
            Value::Object(o) => Ok(o),
            _ => Err(self.expected(what)),
        }
    }

    /// Elements between `open` and `close`, separated by commas.
    fn items<'de, V: Visitor<'de>>(mut self, open: &str, close: &str, visitor: V) -> R<V::Value> {
        let items = self.list("a list")?;
        self.out.push_str(open);
        let path = self.path.clone();
        let r = visitor.visit_seq(Items {
            items,
            next: 0,
            parent: &mut self,
        });
        self.out.push_str(close);
        r.map_err(|e| e.at(&path))
    }

    /// A struct's fields `(name: value, …)` (`struct_like`) or a map's entries `{"key": value}`.
    fn fields<'de, V: Visitor<'de>>(mut self, struct_like: bool, visitor: V) -> R<V::Value> {
        let entries = self.dict(if struct_like {
            "a dict of fields"
        } else {
            "a dict"
        })?;
        if struct_like {
            if let Some(bad) = entries.keys().find(|k| !is_identifier(k)) {
                return Err(DictError {
                    path: Some(self.path.clone()),
                    message: format!("{bad:?} is not a field name"),
                });
            }
        }
        self.out.push_str(if struct_like { "(" } else { "{" });
        let path = self.path.clone();
        let r = visitor.visit_map(Entries {
            entries: entries.iter().collect(),
            next: 0,
            struct_like,
            parent: &mut self,
        });
        self.out.push_str(if struct_like { ")" } else { "}" });
        r.map_err(|e| e.at(&path))
    }
}

struct Items<'p, 'a> {
    items: &'a [Value],
    next: usize,
    parent: &'p mut Ron<'a>,
}

impl<'de, 'a> de::SeqAccess<'de> for Items<'_, 'a> {
    type Error = DictError;
    fn next_element_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> R<Option<T::Value>> {
        let Some(v) = self.items.get(self.next) else {
            return Ok(None);
        };
        if self.next > 0 {
            self.parent.out.push_str(", ");
        }
        let i = self.next;
        self.next += 1;
        seed.deserialize(self.parent.child(v, &format!("[{i}]")))
            .map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.items.len() - self.next)
    }
}

struct Entries<'p, 'a> {
    entries: Vec<(&'a String, &'a Value)>,
    next: usize,
    struct_like: bool,
    parent: &'p mut Ron<'a>,
}

impl<'de, 'a> de::MapAccess<'de> for Entries<'_, 'a> {
    type Error = DictError;
    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> R<Option<K::Value>> {
        let Some((k, _)) = self.entries.get(self.next) else {
            return Ok(None);
        };
        let key = seed
            .deserialize(k.as_str().into_deserializer())
            .map_err(|e: DictError| e.at(&self.parent.path))?;
        if self.next > 0 {
            self.parent.out.push_str(", ");
        }
        if self.struct_like {
            self.parent.out.push_str(k);
        } else {
            self.parent.out.push_str(&quoted(k));
        }
        self.parent.out.push_str(": ");
        Ok(Some(key))
    }
    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> R<V::Value> {
        let (k, v) = self.entries[self.next];
        self.next += 1;
        let segment = if self.struct_like {
            k.clone()
        } else {
            format!("[{}]", quoted(k))
        };
        seed.deserialize(self.parent.child(v, &segment))
    }
}

/// An enum variant: `"Name"` or `{"Name": content}`.
struct Variant<'p, 'a> {
    name: &'a str,
    content: Option<&'a Value>,
    parent: &'p mut Ron<'a>,
}

impl<'de, 'p, 'a> de::EnumAccess<'de> for Variant<'p, 'a> {
    type Error = DictError;
    type Variant = Self;
    fn variant_seed<V: DeserializeSeed<'de>>(self, seed: V) -> R<(V::Value, Self)> {
        let v = seed
            .deserialize(self.name.into_deserializer())
            .map_err(|e: DictError| e.at(&self.parent.path))?;
        self.parent.out.push_str(self.name);
        Ok((v, self))
    }
}

impl<'de> de::VariantAccess<'de> for Variant<'_, '_> {
    type Error = DictError;
    fn unit_variant(self) -> R<()> {
        match self.content {
            None | Some(Value::Null) => Ok(()),
            Some(_) => Err(DictError {
                path: Some(self.parent.path.clone()),
                message: format!("variant {} takes no value", self.name),
            }),
        }
    }
    fn newtype_variant_seed<T: DeserializeSeed<'de>>(self, seed: T) -> R<T::Value> {
        let v = self.content.ok_or_else(|| DictError {
            path: Some(self.parent.path.clone()),
            message: format!("variant {} needs a value: {{\"{0}\": …}}", self.name),
        })?;
        self.parent.out.push('(');
        let r = seed.deserialize(self.parent.child(v, self.name));
        self.parent.out.push(')');
        r
    }
    fn tuple_variant<V: Visitor<'de>>(self, _len: usize, visitor: V) -> R<V::Value> {
        let v = self.content.unwrap_or(&NULL);
        self.parent.child(v, self.name).items("(", ")", visitor)
    }
    fn struct_variant<V: Visitor<'de>>(
        self,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> R<V::Value> {
        let v = self.content.unwrap_or(&NULL);
        self.parent.child(v, self.name).fields(true, visitor)
    }
}

macro_rules! forward_to_any {
    ($($method:ident)*) => {
        $(fn $method<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
            self.deserialize_any(visitor)
        })*
    };
}

impl<'de> de::Deserializer<'de> for Ron<'_> {
    type Error = DictError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        let path = self.path.clone();
        let r = match self.v {
            Value::Null => {
                self.out.push_str("None");
                visitor.visit_none()
            }
            Value::Bool(b) => {
                self.out.push_str(if *b { "true" } else { "false" });
                visitor.visit_bool(*b)
            }
            Value::Number(n) => {
                if let Some(i) = n.as_u64() {
                    write!(self.out, "{i}").expect("writes to a String");
                    visitor.visit_u64(i)
                } else if let Some(i) = n.as_i64() {
                    write!(self.out, "{i}").expect("writes to a String");
                    visitor.visit_i64(i)
                } else {
                    let f = n.as_f64().unwrap_or(f64::NAN);
                    write!(self.out, "{f:?}").expect("writes to a String");
                    visitor.visit_f64(f)
                }
            }
            Value::String(s) => {
                self.out.push_str(&quoted(s));
                visitor.visit_str(s)
            }
            Value::Array(_) => self.items("[", "]", visitor),
            Value::Object(_) => self.fields(false, visitor),
        };
        r.map_err(|e| e.at(&path))
    }

    forward_to_any! {
        deserialize_bool deserialize_i8 deserialize_i16 deserialize_i32 deserialize_i64
        deserialize_u8 deserialize_u16 deserialize_u32 deserialize_u64 deserialize_char
        deserialize_str deserialize_string deserialize_bytes deserialize_byte_buf
        deserialize_identifier deserialize_ignored_any
    }

    fn deserialize_f32<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        self.deserialize_f64(visitor)
    }

    fn deserialize_f64<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        match self.v {
            Value::Number(n) => {
                let f = n.as_f64().unwrap_or(f64::NAN);
                // `{:?}` always writes a decimal point, which RON needs for a float.
                write!(self.out, "{f:?}").expect("writes to a String");
                visitor
                    .visit_f64(f)
                    .map_err(|e: DictError| e.at(&self.path))
            }
            _ => Err(self.expected("a number")),
        }
    }

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        if self.v.is_null() {
            self.out.push_str("None");
            visitor.visit_none()
        } else {
            visitor.visit_some(self)
        }
    }

    fn deserialize_unit<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        self.out.push_str("()");
        visitor.visit_unit()
    }

    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> R<V::Value> {
        self.deserialize_unit(visitor)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> R<V::Value> {
        self.out.push('(');
        let Ron { v, out, path } = self;
        let r = visitor.visit_newtype_struct(Ron {
            v,
            out: &mut *out,
            path,
        });
        out.push(')');
        r
    }

    fn deserialize_seq<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        self.items("[", "]", visitor)
    }

    fn deserialize_tuple<V: Visitor<'de>>(self, _len: usize, visitor: V) -> R<V::Value> {
        self.items("(", ")", visitor)
    }

    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _len: usize,
        visitor: V,
    ) -> R<V::Value> {
        self.items("(", ")", visitor)
    }

    fn deserialize_map<V: Visitor<'de>>(self, visitor: V) -> R<V::Value> {
        self.fields(false, visitor)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> R<V::Value> {
        self.fields(true, visitor)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> R<V::Value> {
        let path = self.path.clone();
        let (name, content) = match self.v {
            Value::String(s) => (s.as_str(), None),
            Value::Object(o) if o.len() == 1 => {
                let (k, v) = o.iter().next().expect("one entry");
                (k.as_str(), Some(v))
            }
            _ => {
                return Err(
                    self.expected("a variant: \"Name\" or a dict with one key {\"Name\": value}")
                )
            }
        };
        let mut me = self;
        visitor
            .visit_enum(Variant {
                name,
                content,
                parent: &mut me,
            })
            .map_err(|e| e.at(&path))
    }
}

/// The RON text of the scene `json` (a dict as JSON text), checked against the scene format.
pub fn dict_to_ron(json: &str) -> Result<String, String> {
    let v: Value = serde_json::from_str(json).map_err(|e| format!("scene dict: {e}"))?;
    let mut out = String::new();
    SceneFile::deserialize(Ron {
        v: &v,
        out: &mut out,
        path: String::new(),
    })
    .map_err(|e| format!("scene dict: {e}"))?;
    Ok(format!("Scene{out}\n"))
}

/// RON text of a scene given as a dict (JSON text from `json.dumps`); raises CandelaError
/// naming the field path of what the scene format refuses.
#[pyfunction]
fn scene_dict_to_ron(json: &str) -> PyResult<String> {
    dict_to_ron(json).map_err(error_msg)
}

/// Parses scene text (syntax, types, unknown fields); `name` stands for the file in messages.
#[pyfunction]
fn check_scene_text(text: &str, name: &str) -> PyResult<()> {
    crate::scene::parse(text, std::path::Path::new(name))
        .map(|_| ())
        .map_err(|e| error_msg(e.to_string()))
}

/// Loads and builds a scene file as a render would (every value checked, files it refers to
/// read); returns the image size (width, height) in pixels.
#[pyfunction]
fn check_scene_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<(usize, usize)> {
    py.detach(|| {
        crate::scene::load_world(&path, &crate::scene::Overrides::default())
            .map(|world| (world.camera.width, world.camera.height))
            .map_err(|e| error(e.into()))
    })
}

/// The text of a scene file, read as the command line reads it (at most
/// [`crate::limits::MAX_TEXT_BYTES`] of UTF-8; never a FIFO, device or directory) and parsed
/// (syntax, types, unknown fields).
#[pyfunction]
fn read_scene_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<String> {
    py.detach(|| {
        let text = crate::limits::read_text(&path, crate::limits::MAX_TEXT_BYTES)
            .map_err(|e| {
                anyhow::Error::new(e).context(format!("cannot read scene file {}", path.display()))
            })
            .map_err(error)?;
        crate::scene::parse(&text, &path).map_err(|e| error_msg(e.to_string()))?;
        Ok(text)
    })
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(scene_dict_to_ron, m)?)?;
    m.add_function(wrap_pyfunction!(check_scene_text, m)?)?;
    m.add_function(wrap_pyfunction!(check_scene_file, m)?)?;
    m.add_function(wrap_pyfunction!(read_scene_file, m)?)?;
    Ok(())
}
