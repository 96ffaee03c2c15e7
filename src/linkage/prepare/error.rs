//! Why a body cannot be prepared from a mesh or an outline.

use crate::Real;

/// Why a body cannot be prepared from a triangle mesh or an outline. Vertex, face, loop and
/// point numbers are 1-based, in file order.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PrepareError {
    /// A spacing that is zero, negative, NaN or infinite.
    #[error("spacing = {spacing} m is not allowed: give the target member length as a finite length greater than 0 m")]
    BadSpacing {
        /// The spacing given, m.
        spacing: Real,
    },
    /// A spacing too large for the part: the lattice would not resolve it.
    #[error("spacing = {spacing} m is larger than the part (its smallest extent is {extent} m): give a spacing below {limit} m so the part is at least a few members thick")]
    SpacingTooLarge {
        /// The spacing given, m.
        spacing: Real,
        /// The part's smallest bounding-box extent, m.
        extent: Real,
        /// The largest spacing accepted, m.
        limit: Real,
    },
    /// A spacing so small that the body would not fit in memory.
    #[error("spacing = {spacing} m would make about {members:.3e} members (about {gigabytes:.3e} GB while preparing, at most {limit_gigabytes:.1} GB): give a spacing of at least {smallest} m")]
    TooLarge {
        /// The spacing given, m.
        spacing: Real,
        /// Estimated members (a float: an absurd spacing gives more than a u64 holds).
        members: Real,
        /// Estimated memory while preparing, GB.
        gigabytes: Real,
        /// The memory allowed, GB.
        limit_gigabytes: Real,
        /// The smallest spacing within the limit, m.
        smallest: Real,
    },
    /// Asked to stop (SIGINT, SIGTERM) while preparing: nothing was made.
    #[error("interrupted while preparing the body: nothing was made")]
    Interrupted,
    /// A triangle whose corners are (nearly) on one line.
    #[error("face {face} (vertices {}, {}, {}) has no area: remove it or merge its vertices", .vertices[0], .vertices[1], .vertices[2])]
    DegenerateFace {
        /// The face, 1-based.
        face: usize,
        /// Its vertices, 1-based.
        vertices: [usize; 3],
    },
    /// Two faces that cross each other away from their shared edges and vertices.
    #[error("face {} and face {} cross each other (near {:?} m): the surface intersects itself; repair the mesh so that faces meet only at shared edges", .faces[0], .faces[1], .at)]
    SelfIntersecting {
        /// The two faces, 1-based.
        faces: [usize; 2],
        /// A point of the first face near the crossing, m.
        at: [Real; 3],
    },
    /// A mesh whose faces enclose no volume once turned outward.
    #[error("the mesh encloses no volume ({volume:e} m³): a body mesh must be a closed surface around the part")]
    NoVolume {
        /// The enclosed volume, m³.
        volume: Real,
    },
    /// The lattice found no interior at this spacing, or a body of pieces.
    #[error("at spacing {spacing} m the prepared body {problem}: give a smaller spacing (at most about a third of the part's thinnest wall)")]
    Unresolved {
        /// The spacing given, m.
        spacing: Real,
        /// What came out, e.g. "has no members" or "falls into 3 pieces".
        problem: String,
    },
    /// A mesh the surface queries cannot be built on (parry's reason).
    #[error(
        "the mesh cannot be used as a closed surface: {0}: check it is one closed, outward surface"
    )]
    Mesh(String),
    /// An outline with a problem: too few points, a crossing, a hole outside the outside loop.
    #[error("outline: {0}")]
    Outline(String),
}
