//! Which texture coordinate sets a mesh is uploaded with: those a texture of its objects
//! reads. A set that nothing samples would cost 8 bytes a vertex for nothing; the shaders read
//! an absent one as a constant.

use crate::scene::Mesh;

/// The coordinate sets uploaded: glTF's `TEXCOORD_0` (`first`, an OBJ's `vt`) and
/// `TEXCOORD_1` (`second`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UvSets {
    /// `TEXCOORD_0`, `a_uv`.
    pub first: bool,
    /// `TEXCOORD_1`, `a_uv1`.
    pub second: bool,
}

impl UvSets {
    /// Both sets, where the mesh has them.
    pub const ALL: UvSets = UvSets {
        first: true,
        second: true,
    };

    /// Those of `self` that `mesh` has.
    pub fn on(self, mesh: &Mesh) -> UvSets {
        UvSets {
            first: self.first && !mesh.uvs.is_empty(),
            second: self.second && !mesh.second_uvs.is_empty(),
        }
    }

    /// The sets of either.
    pub fn union(self, other: UvSets) -> UvSets {
        UvSets {
            first: self.first || other.first,
            second: self.second || other.second,
        }
    }

    /// Whether every set of `other` is one of `self`'s.
    pub fn contains(self, other: UvSets) -> bool {
        (self.first || !other.first) && (self.second || !other.second)
    }
}
