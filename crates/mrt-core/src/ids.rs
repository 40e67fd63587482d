//! Identifiers of the DCDT vocabulary (MRT manual §3.1 and §3.3.3).

use serde::{Deserialize, Serialize};
use std::fmt;

macro_rules! id_type {
    ($(#[$doc:meta])* $name:ident, $prefix:literal) => {
        $(#[$doc])*
        #[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
        pub struct $name(pub u32);

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }

        impl From<u32> for $name {
            fn from(v: u32) -> Self {
                Self(v)
            }
        }
    };
}

id_type!(
    /// "A number that identifies the Agora where the Message has been created" (§3.3.3).
    ///
    /// Every Agora of a community (one process or a network of them) must have its own id.
    AgoraId,
    "agora#"
);
id_type!(
    /// "A number that identifies the Member that created the Message" (§3.3.3).
    ///
    /// Unique inside its Agora; `(AgoraId, MemberId)` is unique in a community.
    MemberId,
    "member#"
);
id_type!(
    /// "A number that identifies unequivocally the type of Message" (§3.3.3).
    ///
    /// All Agoras of a community share the same list of message types (§3.2). Typed Rust
    /// messages declare theirs once, in their `Message` implementation.
    MsgType,
    "type#"
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_display_with_their_kind() {
        assert_eq!(AgoraId(3).to_string(), "agora#3");
        assert_eq!(MemberId(7).to_string(), "member#7");
        assert_eq!(MsgType(42).to_string(), "type#42");
        assert_eq!(MsgType::from(5), MsgType(5));
    }
}
