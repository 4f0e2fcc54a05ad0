//! Gwyddion native `.gwy` files (GWYP serialisation).
//!
//! After the magic `GWYP`, one serialised object: its type name (NUL-terminated), the byte
//! size of its components (u32, little-endian), then the components, each a NUL-terminated
//! name, a one-letter type and a value: `b` bool, `c` char, `i` i32, `q` i64, `d` f64, `s`
//! string, `o` object; upper case for arrays (`C I Q D S O`) prefixed by a u32 count. The top
//! object is a `GwyContainer` whose `/N/data` components are the channels (`GwyDataField`:
//! `xres`, `yres`, `xreal`, `yreal`, `si_unit_xy`, `si_unit_z`, `data`) and `/N/data/title`
//! their titles. Values are in base SI units; rows are stored top first.
//!
//! Masks (`/N/mask`) are user selections, not missing data: they are ignored.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::BTreeMap;

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::quantity::metres_per;

pub struct Gwy;

/// Objects nest (containers in containers); deeper nesting than this is a corrupt file, and
/// refusing it keeps recursion off the end of the stack.
const MAX_DEPTH: usize = 32;

const TOP_FIRST_F64: Stored = Stored { sample: Sample::F64, endian: Endian::Little, bottom_first: false };

impl Format for Gwy {
    fn name(&self) -> &'static str {
        "gwy"
    }

    fn size_field(&self) -> &'static str {
        "xreal and yreal"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["gwy"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(b"GWYP")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// Every channel of the file; errors may quote the file's own (possibly corrupt) text.
fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let body = bytes.strip_prefix(b"GWYP").ok_or("not a Gwyddion file: no GWYP magic")?;
    let mut c = Cursor::new(body, Endian::Little);
    let top = Object::parse(&mut c, 0)?;
    if top.name != "GwyContainer" {
        return Err(format!("not a Gwyddion data file: its top object is a {}", binary::printable(&top.name)));
    }
    let mut fields: BTreeMap<u32, &Object> = BTreeMap::new();
    let mut titles: BTreeMap<u32, &str> = BTreeMap::new();
    for (key, value) in &top.items {
        let Some((id, rest)) = key.strip_prefix('/').and_then(|k| k.split_once('/')) else { continue };
        let Ok(id) = id.parse::<u32>() else { continue };
        match (rest, value) {
            ("data", Value::Object(o)) if o.name == "GwyDataField" => {
                fields.insert(id, o);
            }
            ("data/title", Value::Str(t)) => {
                titles.insert(id, t);
            }
            _ => {}
        }
    }
    if fields.is_empty() {
        return Err("the Gwyddion file holds no image channel (GwyDataField)".into());
    }
    fields.into_iter().map(|(id, o)| data_field(o, titles.get(&id).copied(), id)).collect()
}

/// A deserialised value. Large numeric arrays stay as byte slices, decoded only when used.
enum Value<'a> {
    Int(i64),
    Double(f64),
    Str(String),
    Object(Object<'a>),
    Doubles(&'a [u8]),
    Other,
}

struct Object<'a> {
    name: String,
    items: Vec<(String, Value<'a>)>,
}

impl<'a> Object<'a> {
    fn parse(c: &mut Cursor<'a>, depth: usize) -> Result<Object<'a>, String> {
        if depth > MAX_DEPTH {
            return Err("corrupt Gwyddion file: objects nested too deep".into());
        }
        let name = c.cstr("object name")?;
        let size = c.u32("object size")? as usize;
        // The components must lie within the declared size, which must lie within the file.
        let body = c.take(size, &format!("object {}", binary::printable(&name)))?;
        let mut inner = Cursor::new(body, Endian::Little);
        let mut items = Vec::new();
        while inner.pos() < size {
            let key = inner.cstr("component name")?;
            let kind = inner.u8("component type")?;
            let value = Value::parse(&mut inner, kind, depth)
                .map_err(|e| format!("{}/{}: {e}", binary::printable(&name), binary::printable(&key)))?;
            items.push((key, value));
        }
        Ok(Object { name, items })
    }

    fn get(&self, key: &str) -> Option<&Value<'a>> {
        self.items.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }
}

impl<'a> Value<'a> {
    fn parse(c: &mut Cursor<'a>, kind: u8, depth: usize) -> Result<Value<'a>, String> {
        Ok(match kind {
            b'b' | b'c' => Value::Int(c.u8("value")?.into()),
            b'i' => Value::Int(c.i32("value")?.into()),
            b'q' => Value::Int(c.i64("value")?),
            b'd' => Value::Double(c.f64("value")?),
            b's' => Value::Str(c.cstr("string")?),
            b'o' => Value::Object(Object::parse(c, depth + 1)?),
            b'C' | b'I' | b'Q' | b'D' => {
                let size = match kind {
                    b'C' => 1,
                    b'I' => 4,
                    _ => 8,
                };
                let n = c.u32("array length")? as usize;
                let len = n.checked_mul(size).ok_or("the declared array length overflows")?;
                let raw = c.take(len, "array")?;
                if kind == b'D' {
                    Value::Doubles(raw)
                } else {
                    Value::Other
                }
            }
            b'S' | b'O' => {
                // Each element takes at least one byte, so the count is bounded by the bytes
                // present; nothing is allocated from it.
                let n = c.u32("array length")?;
                for _ in 0..n {
                    if kind == b'S' {
                        c.cstr("string")?;
                    } else {
                        Object::parse(c, depth + 1)?;
                    }
                }
                Value::Other
            }
            k => return Err(format!("corrupt Gwyddion file: unknown component type {:?}", char::from(k))),
        })
    }
}

fn data_field(o: &Object, title: Option<&str>, id: u32) -> Result<Channel, String> {
    let name = title.map(str::to_string).unwrap_or_else(|| format!("Unknown channel {id}"));
    let what = format!("channel '{}'", binary::printable(&name));
    let int = |k: &str| match o.get(k) {
        Some(Value::Int(v)) => usize::try_from(*v).map_err(|_| format!("{what}: negative {k}")),
        _ => Err(format!("{what}: no {k}")),
    };
    let real = |k: &str| match o.get(k) {
        Some(Value::Double(v)) if v.is_finite() && *v > 0.0 => Some(*v),
        _ => None,
    };
    let unit = |k: &str| match o.get(k) {
        Some(Value::Object(u)) => match u.get("unitstr") {
            Some(Value::Str(s)) => s.trim().to_string(),
            _ => String::new(),
        },
        _ => String::new(),
    };
    let (nx, ny) = (int("xres")?, int("yres")?);
    let Some(Value::Doubles(raw)) = o.get("data") else {
        return Err(format!("{what}: no data array"));
    };
    let n = binary::grid_points(nx, ny).map_err(|e| format!("{what}: {e}"))?;
    if raw.len() / 8 != n {
        return Err(format!("{what}: {} values for a {nx} x {ny} grid", raw.len() / 8));
    }
    // Gwyddion keeps values in the base unit whatever prefix the unit string carries.
    let (z_unit, xy_unit) = (unit("si_unit_z"), unit("si_unit_xy"));
    let data = binary::grid(raw, 0, (nx, ny), TOP_FIRST_F64, &what, |v| v)?;
    let physical_size = metres_per(&xy_unit).and(real("xreal").zip(real("yreal")));
    Ok(Channel {
        name,
        data,
        physical_size,
        is_height: metres_per(&z_unit).is_some(),
        unit: Some(z_unit).filter(|u| !u.is_empty()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A serialised object: name, size, components.
    fn object(name: &str, components: &[Vec<u8>]) -> Vec<u8> {
        let body: Vec<u8> = components.concat();
        let mut out = [name.as_bytes(), b"\0"].concat();
        out.extend_from_slice(&(body.len() as u32).to_le_bytes());
        out.extend(body);
        out
    }

    fn component(name: &str, kind: u8, value: &[u8]) -> Vec<u8> {
        [name.as_bytes(), b"\0", &[kind], value].concat()
    }

    fn string(s: &str) -> Vec<u8> {
        [s.as_bytes(), b"\0"].concat()
    }

    fn unit(s: &str) -> Vec<u8> {
        object("GwySIUnit", &[component("unitstr", b's', &string(s))])
    }

    fn field(nx: u32, ny: u32, values: &[f64], z_unit: &str) -> Vec<u8> {
        let data: Vec<u8> = (values.len() as u32)
            .to_le_bytes()
            .into_iter()
            .chain(values.iter().flat_map(|v| v.to_le_bytes()))
            .collect();
        object(
            "GwyDataField",
            &[
                component("xres", b'i', &nx.to_le_bytes()),
                component("yres", b'i', &ny.to_le_bytes()),
                component("xreal", b'd', &4e-6f64.to_le_bytes()),
                component("yreal", b'd', &2e-6f64.to_le_bytes()),
                component("si_unit_xy", b'o', &unit("m")),
                component("si_unit_z", b'o', &unit(z_unit)),
                component("data", b'D', &data),
            ],
        )
    }

    #[test]
    fn channels_in_id_order_with_titles_and_other_components_skipped() {
        let container = object(
            "GwyContainer",
            &[
                component("/3/data", b'o', &field(2, 1, &[5.0, 6.0], "V")),
                component("/0/data/title", b's', &string("Topography")),
                // Components the reader must step over: arrays of every kind, a nested object.
                component("/0/meta/strings", b'S', &[2u32.to_le_bytes().to_vec(), string("a"), string("bc")].concat()),
                component("/0/ints", b'I', &[1u32.to_le_bytes(), 7u32.to_le_bytes()].concat()),
                component("/0/flag", b'b', &[1]),
                component("/0/objs", b'O', &[1u32.to_le_bytes().to_vec(), unit("s")].concat()),
                component("/0/data", b'o', &field(2, 2, &[1e-9, 2e-9, 3e-9, 4e-9], "m")),
                component("/0/mask", b'o', &field(2, 2, &[0.0, 1.0, 0.0, 0.0], "")),
            ],
        );
        let bytes = [b"GWYP".to_vec(), container].concat();
        let ch = Gwy.read(&bytes).unwrap();
        assert_eq!(ch.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), ["Topography", "Unknown channel 3"]);
        assert_eq!(ch[0].data, ndarray::array![[1e-9, 2e-9], [3e-9, 4e-9]]);
        assert_eq!(ch[0].physical_size, Some((4e-6, 2e-6)));
        assert!(ch[0].is_height && !ch[1].is_height);
        assert_eq!(ch[1].unit.as_deref(), Some("V"));

        // The object size pointing past the end of the file.
        let mut bad = bytes.clone();
        let at = 4 + "GwyContainer\0".len();
        bad[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(Gwy.read(&bad).unwrap_err().contains("truncated"));
    }

    #[test]
    fn a_data_count_not_matching_the_grid_is_refused() {
        let container = object("GwyContainer", &[component("/0/data", b'o', &field(3, 2, &[1.0; 5], "m"))]);
        let err = Gwy.read(&[b"GWYP".to_vec(), container].concat()).unwrap_err();
        assert!(err.contains("5 values for a 3 x 2 grid"), "{err}");
    }
}
