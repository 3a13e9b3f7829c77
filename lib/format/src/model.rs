//! The container's data model (format-spec/SPEC.md, section "Model").

/// A field enum of the file format: its variants, their codes in the file and their names
/// in reports. Generates `ALL`, `from_code`, `code` and `name`.
macro_rules! coded_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident: $repr:ty {
            $( $(#[$vmeta:meta])* $variant:ident = $code:literal => $text:literal, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $code, )+
        }

        impl $name {
            /// Every variant, in code order.
            pub const ALL: [$name; <[&str]>::len(&[$(stringify!($variant)),+])] = [$($name::$variant),+];

            /// The variant stored as `code`, if the format defines it.
            pub fn from_code(code: $repr) -> Option<Self> {
                Self::ALL.into_iter().find(|v| v.code() == code)
            }

            /// The value stored in the file.
            pub fn code(self) -> $repr {
                self as $repr
            }

            /// The name used in reports and JSON.
            pub fn name(self) -> &'static str {
                match self {
                    $( $name::$variant => $text, )+
                }
            }
        }
    };
}

coded_enum! {
    /// What a parameter dimension varies (SPEC.md, `PSPC` chunk, field `kind`).
    pub enum DimensionKind: u8 {
        /// The viewpoint moves.
        View = 0 => "view",
        /// A light moves or changes.
        Light = 1 => "light",
        /// An object moves rigidly.
        ObjectMotion = 2 => "object_motion",
        /// Time in an animation that is none of the above.
        Time = 3 => "time",
        /// Anything else.
        Other = 4 => "other",
    }
}

coded_enum! {
    /// How an object is shaded and therefore represented (SPEC.md, `OBJS` chunk, field `role`).
    pub enum ObjectRole: u8 {
        /// Parameterized surface textures only.
        Diffuse = 0 => "diffuse",
        /// Surface textures plus layered environment-map shells modulated by Fresnel.
        Reflective = 1 => "reflective",
        /// A refractive lens object: hybrid rendering with a two-term shading model.
        Refractive = 2 => "refractive",
    }
}

/// A container: everything a `.pis` file holds. `S` is how level images are held: owned
/// [`Codestream`]s when building or fully loaded, [`StreamRef`]s (offsets into the file) when
/// opened for random access.
#[derive(Clone, Debug, PartialEq)]
pub struct Container<S = Codestream> {
    pub space: ParameterSpace,
    pub cameras: CameraTable,
    pub objects: Vec<Object<S>>,
    pub provenance: Option<Provenance>,
}

/// The parameter space (chunk `PSPC`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ParameterSpace {
    pub dims: Vec<Dimension>,
}

impl ParameterSpace {
    /// Number of parameter points.
    pub fn point_count(&self) -> u64 {
        self.dims.iter().map(|d| d.values.len() as u64).product()
    }

    /// Number of entries of a table that depends on the dimensions in `mask`.
    pub fn table_len(&self, mask: DepMask) -> u64 {
        mask.dims().filter_map(|k| self.dims.get(k)).map(|d| d.values.len() as u64).product()
    }

    /// Index into a table that depends on `mask`, for the point with sample indices `point`
    /// (row-major over the masked dimensions, the last one fastest).
    pub fn table_index(&self, mask: DepMask, point: &[u32]) -> usize {
        let mut index = 0usize;
        for k in mask.dims() {
            index = index * self.dims[k].values.len() + point[k] as usize;
        }
        index
    }

    /// Sample indices of the point with linear index `index` (the last dimension fastest).
    pub fn point(&self, mut index: u64) -> Vec<u32> {
        let mut out = vec![0; self.dims.len()];
        for (k, d) in self.dims.iter().enumerate().rev() {
            let n = d.values.len() as u64;
            out[k] = (index % n) as u32;
            index /= n;
        }
        out
    }

    /// Sample indices nearest to the continuous values `values` (one per dimension).
    pub fn nearest(&self, values: &[f32]) -> Vec<u32> {
        self.dims
            .iter()
            .zip(values)
            .map(|(d, v)| {
                let mut best = 0;
                for (i, s) in d.values.iter().enumerate() {
                    if (s - v).abs() < (d.values[best] - v).abs() {
                        best = i;
                    }
                }
                best as u32
            })
            .collect()
    }
}

/// One named dimension of the parameter space.
#[derive(Clone, Debug, PartialEq)]
pub struct Dimension {
    pub name: String,
    pub kind: DimensionKind,
    /// The dimension wraps around (its last sample neighbours its first).
    pub periodic: bool,
    /// Unit of the sample values ("deg", "s", ...), may be empty.
    pub unit: String,
    /// Parameter-space block size along this dimension (section 4.1).
    pub block_size: u32,
    /// The value of every sample, strictly increasing.
    pub values: Vec<f32>,
}

/// A set of dimensions a table depends on: bit k set = depends on dimension k.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct DepMask(pub u32);

impl DepMask {
    pub const NONE: DepMask = DepMask(0);

    pub fn of(dims: &[usize]) -> Self {
        DepMask(dims.iter().fold(0, |m, &k| m | (1 << k)))
    }

    /// The dimension indices in the mask, ascending.
    pub fn dims(self) -> impl Iterator<Item = usize> {
        (0..32).filter(move |k| self.0 & (1 << k) != 0)
    }

    pub fn count(self) -> usize {
        self.0.count_ones() as usize
    }

    pub fn contains(self, k: usize) -> bool {
        k < 32 && self.0 & (1 << k) != 0
    }
}

/// The cameras of the view samples (chunk `CAMS`).
#[derive(Clone, Debug, PartialEq)]
pub struct CameraTable {
    /// Size of the ray-traced images, in pixels.
    pub width: u32,
    pub height: u32,
    /// The dimensions the camera depends on (usually the view dimensions).
    pub depends_on: DepMask,
    /// One camera per combination of the masked dimensions' samples.
    pub cameras: Vec<Camera>,
}

/// A perspective camera looking down its local -Z with +Y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Rigid camera-to-world transform, 3 rows × 4 columns, row-major.
    pub world_from_camera: [f32; 12],
    /// Vertical field of view, radians, in (0, π).
    pub yfov: f32,
    pub znear: f32,
    /// May be +∞.
    pub zfar: f32,
}

/// The 3×4 identity transform.
pub const IDENTITY_3X4: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// One object: geometry, role, shading constants and its texture layers.
#[derive(Clone, Debug, PartialEq)]
pub struct Object<S = Codestream> {
    pub name: String,
    pub role: ObjectRole,
    pub shading: Shading,
    /// Block origin offset per dimension (section 4.7, staggering); each < the block size.
    pub stagger: Vec<u32>,
    /// Rigid object-to-world transforms, one per combination of the masked dimensions.
    pub transforms: TransformTable,
    pub mesh: Mesh,
    pub layers: Vec<Layer<S>>,
}

/// Constants the player needs to shade an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// Reflectance at normal incidence (Schlick's F0), linear RGB in [0, 1].
    pub f0: [f32; 3],
    /// Index of refraction (≥ 1).
    pub ior: f32,
    /// Beer–Lambert absorption coefficients per unit length, linear RGB, ≥ 0.
    pub absorption: [f32; 3],
}

impl Default for Shading {
    fn default() -> Self {
        Shading { f0: [0.04; 3], ior: 1.5, absorption: [0.0; 3] }
    }
}

/// Object-to-world transforms over the parameter space.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformTable {
    pub depends_on: DepMask,
    /// 3 rows × 4 columns, row-major.
    pub transforms: Vec<[f32; 12]>,
}

impl TransformTable {
    /// A static object.
    pub fn fixed(t: [f32; 12]) -> Self {
        TransformTable { depends_on: DepMask::NONE, transforms: vec![t] }
    }
}

/// A triangle mesh in object space (chunk `MESH`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub texcoords: Option<Vec<[f32; 2]>>,
    /// Triangle list.
    pub indices: Vec<u32>,
    /// The first `hull_triangles` triangles lie on the object's convex hull: the
    /// reflection term draws them with its most distant shell only (thesis 5.7).
    pub hull_triangles: u32,
}

coded_enum! {
    /// What a layer holds (SPEC.md, table "Layer kinds").
    pub enum LayerKind: u8 {
        /// View-independent radiance of the first diffuse interaction.
        Diffuse = 0 => "diffuse",
        /// View-dependent radiance on the surface.
        Specular = 1 => "specular",
        /// Reflectance texture that multiplies a lighting layer (fig. 4.8).
        Albedo = 2 => "albedo",
        /// Incident lighting that an albedo layer multiplies.
        Lighting = 3 => "lighting",
        /// Local environment-map shell (self-reflections), with alpha.
        EnvLocal = 4 => "env_local",
        /// Distant environment-map shell.
        EnvDistant = 5 => "env_distant",
        /// One shell of a lens object's layered environment map.
        EnvShell = 6 => "env_shell",
    }
}

impl LayerKind {
    /// True for the kinds drawn through an environment-map shell.
    pub fn is_shell(self) -> bool {
        matches!(self, LayerKind::EnvLocal | LayerKind::EnvDistant | LayerKind::EnvShell)
    }
}

coded_enum! {
    /// Which term of the shading model a layer contributes to (SPEC.md, "Combining layers").
    pub enum Term: u8 {
        /// Surface textures, summed (or multiplied) in order.
        Surface = 0 => "surface",
        /// Reflection term: shells composited "over", modulated by Fresnel.
        Reflection = 1 => "reflection",
        /// Refraction term of a lens object: shells composited "over", modulated by
        /// transmission and absorption.
        Refraction = 2 => "refraction",
    }
}

coded_enum! {
    /// How a layer joins the running result of its term.
    pub enum Combine: u8 {
        Add = 0 => "add",
        Multiply = 1 => "multiply",
        /// Porter–Duff "over" with straight alpha: this layer over the layers after it.
        Over = 2 => "over",
    }
}

coded_enum! {
    /// Which MIP levels a level image holds (SPEC.md, "MIP levels").
    pub enum MipMode: u8 {
        /// The finest level only; the player rebuilds the chain by decimation (section 3.6).
        Decimated = 0 => "decimated",
        /// The whole chain; levels below the finest are stored as residuals from the decimated
        /// finest level (section 5.8.1).
        Stored = 1 => "stored",
    }
}

coded_enum! {
    /// How texels reach the screen: through the mesh's texture coordinates, or through an
    /// environment-map shell.
    pub enum Mapping: u8 {
        Surface = 0 => "surface",
        Shell = 1 => "shell",
    }
}

/// One texture field of an object: a parameterized texture or environment-map shell.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer<S = Codestream> {
    pub kind: LayerKind,
    pub mapping: Mapping,
    /// 3 (RGB) or 4 (RGBA, straight alpha; shells only).
    pub channels: u8,
    pub mip_mode: MipMode,
    pub term: Term,
    /// Position within the term: surface layers apply in increasing order; shells composite
    /// from order 0 (nearest) outwards.
    pub order: u8,
    pub combine: Combine,
    /// 0, or c + 1: the layer holds coefficient c of the spherical harmonics of the object's
    /// radiance over the file's light directions (since 1.6; section 7.1).
    pub basis: u8,
    /// Stored values are γ(L) = sign(L)·|L|^(1/gamma); 1 means linear (section 4.6).
    pub gamma: f32,
    /// The dimensions this layer varies over; blocks tile only these.
    pub depends_on: DepMask,
    /// One per block of the layer's block grid, row-major (the last masked dimension fastest).
    pub blocks: Vec<Block<S>>,
}

impl Placement {
    /// A surface placement with the given transform, clamped in both directions.
    pub fn surface(affine: [f32; 6]) -> Self {
        Placement::Surface { affine, repeat: [false; 2], cut: [None; 2] }
    }
}

/// One parameter-space block of a layer: texture placement and its Laplacian pyramid.
#[derive(Clone, Debug, PartialEq)]
pub struct Block<S = Codestream> {
    /// Used texture size (non-power-of-two allowed); a shell's cube face is width × width.
    pub width: u32,
    pub height: u32,
    pub placement: Placement,
    /// Pyramid levels from the top (one sample) to the finest (the block's extent).
    pub levels: Vec<Level<S>>,
}

impl<S> Block<S> {
    /// Whether `other`'s texture is placed as this block's: the same used size and
    /// placement, so a texel means the same surface point in both.
    pub fn same_placement<T>(&self, other: &Block<T>) -> bool {
        (self.width, self.height, self.placement) == (other.width, other.height, other.placement)
    }
}

/// Where a block's texture sits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// Affine texture-coordinate transform (section 3.2):
    /// s = a·u + b·v + e, t = c·u + d·v + f, as `[a, b, c, d, e, f]`; (s, t) in [0, 1]²
    /// spans the used texture. `repeat[0]` / `repeat[1]`: the texture wraps along s / t
    /// (no branch cut was made there); otherwise it is clamped to its edge.
    /// `cut[0]` / `cut[1]`: a branch cut along u / v (thesis 3.2): before the affine
    /// transform, each vertex's coordinate w becomes `(w − cut) − floor(w − cut)`.
    Surface { affine: [f32; 6], repeat: [bool; 2], cut: [Option<f32>; 2] },
    /// Environment-map shell geometry with its cube-map origin, and the lookups per pixel:
    /// `lookups` × `lookups` sub-pixel lookups averaged (1 to [`MAX_SHELL_LOOKUPS`]; SPEC.md
    /// 8.2), stored in the block's flags as `lookups − 1`.
    Shell { shape: ShellShape, origin: [f32; 3], params: [f32; 6], lookups: u32 },
}

/// The most lookups per pixel side of a shell block (SPEC.md 7.3 flags, 8.2).
pub const MAX_SHELL_LOOKUPS: u32 = 3;

coded_enum! {
    /// Environment-map shell geometry (SPEC.md, table "Shell shapes").
    pub enum ShellShape: u32 {
        /// params[0] = radius.
        Sphere = 1 => "sphere",
        /// params[0..3] = radii along x, y, z.
        Ellipsoid = 2 => "ellipsoid",
        /// params[0..3] = min corner, params[3..6] = max corner (world space).
        Box = 3 => "box",
        /// Axis parallel to +Y through the origin: params[0] = radius, [1] = y min, [2] = y max.
        Cylinder = 4 => "cylinder",
        /// A parallelogram: origin = corner, params[0..3] = edge s, params[3..6] = edge t.
        Quad = 5 => "quad",
        /// A star-shaped shell whose radius in every direction is the distance to the scene
        /// about the origin (a depth cube the reader computes from the file's meshes, SPEC.md
        /// 8.5): params[0] = face size n of the depth cube, params[1] = march steps,
        /// params[2] = far distance.
        Depth = 6 => "depth",
    }
}

impl ShellShape {
    /// Number of texture faces: 6 cube faces, or 1 for a quad.
    pub fn faces(self) -> u32 {
        if self == ShellShape::Quad {
            1
        } else {
            6
        }
    }
}

/// One level of a block's adaptive Laplacian pyramid (section 4.3).
#[derive(Clone, Debug, PartialEq)]
pub struct Level<S = Codestream> {
    /// Samples along each of the layer's dimensions at this level.
    pub counts: Vec<u32>,
    /// One level image per sample of this level, row-major.
    pub images: Vec<S>,
}

/// An encoded level image held in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Codestream {
    pub codec: pis_codec::CodecId,
    pub bytes: Vec<u8>,
}

/// Where an encoded level image lies in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamRef {
    pub codec: pis_codec::CodecId,
    /// Index of the `CSTR` chunk in the chunk table.
    pub chunk: u32,
    /// Byte offset within that chunk's payload.
    pub offset: u64,
    pub length: u32,
    /// CRC-32 of the codestream bytes.
    pub crc: u32,
}

/// Where the file came from (chunk `PROV`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Provenance {
    /// The tool and version that wrote the file.
    pub tool: String,
    /// The ray-traced set (or other source) it was made from.
    pub source: String,
    /// Size of the raw image set at 3 bytes per pixel (section 4.8), for compression ratios.
    pub raw_image_bytes: u64,
    /// Settings as key/value pairs, in the order the tool wrote them.
    pub settings: Vec<(String, String)>,
}

impl Provenance {
    /// The value of the first setting named `key`, if any.
    pub fn setting(&self, key: &str) -> Option<&str> {
        self.settings.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
}

impl<S> Container<S> {
    /// Every level image of the file, in file order (object, layer, block, level).
    pub fn level_images(&self) -> impl Iterator<Item = &S> {
        self.objects
            .iter()
            .flat_map(|o| &o.layers)
            .flat_map(|l| &l.blocks)
            .flat_map(|b| &b.levels)
            .flat_map(|l| &l.images)
    }

    /// The same container with every level image converted by `f` (in file order).
    pub fn try_map<T, E>(&self, f: &mut impl FnMut(&S) -> Result<T, E>) -> Result<Container<T>, E> {
        let mut objects = Vec::with_capacity(self.objects.len());
        for o in &self.objects {
            let mut layers = Vec::with_capacity(o.layers.len());
            for l in &o.layers {
                let mut blocks = Vec::with_capacity(l.blocks.len());
                for b in &l.blocks {
                    let mut levels = Vec::with_capacity(b.levels.len());
                    for level in &b.levels {
                        let images =
                            level.images.iter().map(&mut *f).collect::<Result<Vec<_>, E>>()?;
                        levels.push(Level { counts: level.counts.clone(), images });
                    }
                    blocks.push(Block {
                        width: b.width,
                        height: b.height,
                        placement: b.placement,
                        levels,
                    });
                }
                layers.push(Layer {
                    kind: l.kind,
                    mapping: l.mapping,
                    channels: l.channels,
                    mip_mode: l.mip_mode,
                    term: l.term,
                    order: l.order,
                    combine: l.combine,
                    basis: l.basis,
                    gamma: l.gamma,
                    depends_on: l.depends_on,
                    blocks,
                });
            }
            objects.push(Object {
                name: o.name.clone(),
                role: o.role,
                shading: o.shading,
                stagger: o.stagger.clone(),
                transforms: o.transforms.clone(),
                mesh: o.mesh.clone(),
                layers,
            });
        }
        Ok(Container {
            space: self.space.clone(),
            cameras: self.cameras.clone(),
            objects,
            provenance: self.provenance.clone(),
        })
    }
}
