//! Typed indices into the flat arrays of a mesh.
//!
//! Every id is a `u32` newtype, so a vertex index cannot be passed where a face index is
//! expected. `INVALID` (`u32::MAX`) marks "none" in arrays that need a sentinel.

macro_rules! typed_id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
        #[derive(serde::Serialize, serde::Deserialize)]
        #[repr(transparent)]
        pub struct $name(pub u32);

        impl $name {
            /// The sentinel meaning "no element".
            pub const INVALID: Self = Self(u32::MAX);

            /// The id as a `usize`, for indexing arrays.
            #[inline]
            pub const fn idx(self) -> usize {
                self.0 as usize
            }

            /// Whether this id is not the [`Self::INVALID`] sentinel.
            #[inline]
            pub const fn is_valid(self) -> bool {
                self.0 != u32::MAX
            }

            /// Builds an id from a `usize` index.
            ///
            /// # Panics
            /// If `i` does not fit in a `u32` below the sentinel (a broken invariant: meshes are
            /// limited to `u32::MAX - 1` elements of each kind).
            #[inline]
            #[track_caller]
            pub fn from_usize(i: usize) -> Self {
                assert!(i < u32::MAX as usize, "index {i} does not fit a u32 id");
                Self(i as u32)
            }
        }

        impl From<$name> for usize {
            #[inline]
            fn from(id: $name) -> usize {
                id.idx()
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    };
}

typed_id!(
    /// Index of a vertex (a row of the positions array).
    VertexId
);
typed_id!(
    /// Index of a face (a polygon of a [`crate::Polygons`] list).
    FaceId
);
typed_id!(
    /// Index of an undirected edge of a [`crate::HalfEdgeMesh`].
    EdgeId
);
typed_id!(
    /// Index of a directed half-edge of a [`crate::HalfEdgeMesh`].
    HalfEdgeId
);
