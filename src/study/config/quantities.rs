//! Quantities of the study file: a bare number in SI units, or a string with its unit
//! (`"0.1 mN"`, `"31.13 µm"`); a unit of the wrong kind for its key is refused. Lengths,
//! forces, stresses, times, works of adhesion, and a window's size.
//!
//! It must not import the study file's sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use std::fmt;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};

use crate::quantity::{self, Dimension, FORCE, LENGTH, PRESSURE, SURFACE_ENERGY, TIME};

/// Deserialise a bare number (SI) or a string with its unit.
fn deserialize_quantity<'de, D: Deserializer<'de>>(d: D, dim: &'static Dimension) -> Result<f64, D::Error> {
    struct Quantity(&'static Dimension);
    impl Visitor<'_> for Quantity {
        type Value = f64;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "a {} (a number in {} or a string with a unit)", self.0.name, self.0.si)
        }
        fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
            quantity::finite(v, &v.to_string()).map_err(E::custom)
        }
        fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
            Ok(v as f64)
        }
        fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
            Ok(v as f64)
        }
        fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
            quantity::parse(v, self.0, false).map_err(E::custom)
        }
    }
    d.deserialize_any(Quantity(dim))
}

macro_rules! quantity {
    ($(#[$doc:meta])* $name:ident, $dim:expr) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize)]
        #[serde(transparent)]
        pub struct $name(pub f64);

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                deserialize_quantity(d, &$dim).map($name)
            }
        }
    };
}

quantity!(
    /// A length \[m].
    Length,
    LENGTH
);
quantity!(
    /// A force \[N].
    Force,
    FORCE
);
quantity!(
    /// A stress or modulus \[Pa].
    Stress,
    PRESSURE
);
quantity!(
    /// A time \[s].
    Time,
    TIME
);
quantity!(
    /// A work of adhesion \[J/m²].
    SurfaceEnergy,
    SURFACE_ENERGY
);

/// A physical size (lx, ly) \[m]: one length for a square, or two.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Size(pub Length, pub Length);

impl Serialize for Size {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        [self.0, self.1].serialize(s)
    }
}

impl<'de> Deserialize<'de> for Size {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct SizeVisitor;
        impl<'de> Visitor<'de> for SizeVisitor {
            type Value = Size;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a length, or [lx, ly]")
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Size, A::Error> {
                let lx: Length = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let ly: Length = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(1, &self))?;
                if seq.next_element::<Length>()?.is_some() {
                    return Err(de::Error::invalid_length(3, &self));
                }
                Ok(Size(lx, ly))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Size, E> {
                Ok(Size(Length(v), Length(v)))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Size, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Size, E> {
                let l = Length(quantity::parse(v, &LENGTH, false).map_err(E::custom)?);
                Ok(Size(l, l))
            }
        }
        d.deserialize_any(SizeVisitor)
    }
}
