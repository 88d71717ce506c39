//! Options chosen by name. Every option type lists its names once, here in the core; the
//! Python binding converts a `str` through [`Choice::parse`] (`py/convert.rs`, `Wrap<T>`)
//! and Python reads the lists from `_core.OPTIONS`, so a name is checked in one place.

use crate::error::{invalid, Result};

/// An enumeration a user selects by name (`kind="rates"`, `ellipsoid="WGS84"`).
pub trait Choice: Sized + Copy + PartialEq + 'static {
    /// The parameter name under which the option is passed, used in error messages.
    const PARAMETER: &'static str;
    /// Every accepted name with its value, in the order the documentation lists them.
    const CHOICES: &'static [(&'static str, Self)];

    /// The value named `name`, or an `InvalidInput` naming the parameter and listing the
    /// accepted names.
    fn parse(name: &str) -> Result<Self> {
        Self::CHOICES.iter().find(|(n, _)| *n == name).map(|(_, v)| *v).ok_or_else(|| {
            invalid(Self::PARAMETER, format!("unknown option {name:?}; choose one of {}", Self::names().join(", ")))
        })
    }

    /// The accepted names.
    fn names() -> Vec<&'static str> {
        Self::CHOICES.iter().map(|(n, _)| *n).collect()
    }

    /// The name of a value (the first listed when several names map to it).
    fn name(self) -> &'static str {
        Self::CHOICES.iter().find(|(_, v)| *v == self).map_or("", |(n, _)| *n)
    }
}

/// Serde adapter for a field whose type is a [`Choice`]: saved as its name, restored by
/// [`Choice::parse`] (`#[serde(with = "crate::options::by_name")]`). A saved state then
/// reads the same whatever the option's representation in memory.
pub mod by_name {
    use super::Choice;
    use serde::{de::Error, Deserialize, Deserializer, Serializer};

    pub fn serialize<T: Choice, S: Serializer>(v: &T, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(v.name())
    }

    pub fn deserialize<'de, T: Choice, D: Deserializer<'de>>(d: D) -> std::result::Result<T, D::Error> {
        let name = <&str>::deserialize(d)?;
        T::parse(name).map_err(D::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Colour {
        Red,
        Blue,
    }

    impl Choice for Colour {
        const PARAMETER: &'static str = "colour";
        const CHOICES: &'static [(&'static str, Self)] = &[("red", Colour::Red), ("blue", Colour::Blue)];
    }

    #[test]
    fn parse_names_and_rejects() {
        assert_eq!(Colour::parse("blue"), Ok(Colour::Blue));
        assert_eq!(Colour::Red.name(), "red");
        let e = Colour::parse("green").unwrap_err().to_string();
        assert!(e.starts_with("colour: unknown option \"green\"; choose one of red, blue"), "{e}");
    }
}
