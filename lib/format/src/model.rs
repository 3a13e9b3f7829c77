//! The container's data model (format-spec/SPEC.md, section "Model").

/// What a parameter dimension varies (SPEC.md, `PSPC` chunk, field `kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DimensionKind {
    /// The viewpoint moves.
    View = 0,
    /// A light moves or changes.
    Light = 1,
    /// An object moves rigidly.
    ObjectMotion = 2,
    /// Time in an animation that is none of the above.
    Time = 3,
    /// Anything else.
    Other = 4,
}

impl DimensionKind {
    pub const ALL: [DimensionKind; 5] = [
        DimensionKind::View,
        DimensionKind::Light,
        DimensionKind::ObjectMotion,
        DimensionKind::Time,
        DimensionKind::Other,
    ];

    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(code as usize).copied()
    }

    pub fn code(self) -> u8 {
        self as u8
    }

    pub fn name(self) -> &'static str {
        match self {
            DimensionKind::View => "view",
            DimensionKind::Light => "light",
            DimensionKind::ObjectMotion => "object_motion",
            DimensionKind::Time => "time",
            DimensionKind::Other => "other",
        }
    }
}

/// How an object is shaded and therefore represented (SPEC.md, `OBJS` chunk, field `role`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObjectRole {
    /// Parameterized surface textures only.
    Diffuse = 0,
    /// Surface textures plus layered environment-map shells modulated by Fresnel.
    Reflective = 1,
    /// A refractive lens object: hybrid rendering with a two-term shading model.
    Refractive = 2,
}

impl ObjectRole {
    pub const ALL: [ObjectRole; 3] = [ObjectRole::Diffuse, ObjectRole::Reflective, ObjectRole::Refractive];

    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(code as usize).copied()
    }

    pub fn code(self) -> u8 {
        self as u8
    }

    pub fn name(self) -> &'static str {
        match self {
            ObjectRole::Diffuse => "diffuse",
            ObjectRole::Reflective => "reflective",
            ObjectRole::Refractive => "refractive",
        }
    }
}
