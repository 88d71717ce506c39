//! Saved state of a core object: its whole value as bytes (postcard, every f64 bit for
//! bit), behind a header of the format version and the object's name, so bytes of another
//! object or another version are refused instead of misread. Pickle and deepcopy of the
//! Python objects (`py/pickle.rs`) carry these bytes.

use crate::error::{invalid, Result};
use serde::{de::DeserializeOwned, Serialize};

/// Format version of the saved bytes.
pub const VERSION: u32 = 1;

/// `value` saved under `name` (the name `load` must be given back).
pub fn save<T: Serialize>(name: &str, value: &T) -> Result<Vec<u8>> {
    postcard::to_stdvec(&(VERSION, name, value)).map_err(|e| invalid("state", format!("cannot be saved: {e}")))
}

/// The value `save` wrote under `name`; bytes saved under another name or version, or no
/// saved state at all, are `InvalidInput` naming `state`.
pub fn load<T: DeserializeOwned>(name: &str, bytes: &[u8]) -> Result<T> {
    let not_a_state = |e: postcard::Error| invalid("state", format!("not a saved {name} state ({e})"));
    // the tuple (version, name, value) is the concatenation of its parts: read the header first
    let ((version, saved_as), rest): ((u32, String), &[u8]) = postcard::take_from_bytes(bytes).map_err(not_a_state)?;
    if version != VERSION || saved_as != name {
        return Err(invalid("state", format!("a saved {saved_as} state of format {version}, expected {name} of format {VERSION}")));
    }
    postcard::from_bytes(rest).map_err(not_a_state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NavError;

    #[test]
    fn a_value_round_trips_and_other_bytes_are_refused() {
        let v = (1.0f64 / 3.0, vec![f64::MIN_POSITIVE, -0.0], String::from("x"));
        let bytes = save("Thing", &v).unwrap();
        assert_eq!(load::<(f64, Vec<f64>, String)>("Thing", &bytes).unwrap(), v);
        let named = |r: Result<(f64, Vec<f64>, String)>| matches!(r, Err(NavError::InvalidInput { field, .. }) if field == "state");
        assert!(named(load("Other", &bytes)));
        assert!(named(load("Thing", &bytes[..bytes.len() - 3])));
        assert!(named(load("Thing", b"xx")));
        let mut old = bytes.clone();
        old[0] = 0; // version 0
        assert!(named(load("Thing", &old)));
    }
}
