//! Spec structs read from JSON objects only. serde's derived structs also take an array of
//! their fields in order (`"camera": [[0, 2, 8], [0, 1, 0]]`), which the file format does not
//! have: such a file would mean whatever the fields' order in the source happens to be.

/// Implements `Deserialize` for `$spec`, whose derive says `#[serde(remote = "Self")]`: a
/// JSON object as the derive reads it; anything else is an error expecting `$expecting`.
macro_rules! map_only {
    ($spec:ident, $expecting:literal) => {
        impl<'de> serde::Deserialize<'de> for $spec {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                struct ObjectOnly;
                impl<'de> serde::de::Visitor<'de> for ObjectOnly {
                    type Value = $spec;
                    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                        f.write_str($expecting)
                    }
                    fn visit_map<A: serde::de::MapAccess<'de>>(
                        self,
                        map: A,
                    ) -> Result<$spec, A::Error> {
                        // The derive's own function (`remote = "Self"`), not this trait's.
                        $spec::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    }
                }
                d.deserialize_map(ObjectOnly)
            }
        }
    };
}

pub(super) use map_only;
