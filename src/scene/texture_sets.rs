//! Which coordinate set each texture a material samples reads: what a mesh's second set and
//! tangents are uploaded or kept for.

/// The coordinate set each texture a material samples reads, by its glTF name (`None`: not
/// sampled, sampled to no effect as a normal map of scale 0, or not bound).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct TextureSets(pub [(&'static str, Option<u32>); 5]);

impl TextureSets {
    /// Some texture reads the second set (glTF's `TEXCOORD_1`).
    pub fn second(&self) -> bool {
        self.0.iter().any(|(_, set)| *set == Some(1))
    }

    /// The set the normal texture reads (its tangents follow it), if it has one.
    #[cfg_attr(not(feature = "gltf"), allow(dead_code))]
    pub fn normal(&self) -> Option<u32> {
        let normal = self.0.iter().find(|(name, _)| *name == "normalTexture");
        normal.and_then(|(_, set)| *set)
    }

    /// The textures reading `set`, by their glTF names.
    #[cfg_attr(not(feature = "gltf"), allow(dead_code))]
    pub fn named_on(&self, set: u32) -> Vec<&'static str> {
        let on = |(name, s): &(&'static str, Option<u32>)| (*s == Some(set)).then_some(*name);
        self.0.iter().filter_map(on).collect()
    }
}
