//! Small containers built in code: `samples/tiny.pis` and the spec's worked example
//! (`format-spec/examples/minimal.pis`). Tests regenerate both and compare bytes.

use pis_codec::CodecId;

use crate::blocks::{level_image_index, BlockGrid};
use crate::model::*;
use crate::reconstruct::prepare;
use crate::texture::LevelLayout;
use crate::Error;

/// Encodes one block's pyramid from the linear textures of its finest samples (row-major
/// over the block's extent). `level_counts` lists each level's sample counts, top to finest.
/// Each level holds box-filtered means over the samples it covers, minus the levels above,
/// so the sum along any path gives back the finest sample.
pub fn encode_block(
    layer: &Layer<Codestream>,
    mut block: Block<Codestream>,
    extent: &[u32],
    level_counts: &[Vec<u32>],
    samples: &[Vec<f32>],
    codec: CodecId,
) -> Result<Block<Codestream>, Error> {
    let layout = LevelLayout::of(layer, &block);
    let planes = layout.planes();
    let prepared: Vec<Vec<f32>> = samples.iter().map(|s| prepare(layer, &layout, s)).collect();
    let locals: Vec<Vec<u32>> = (0..prepared.len()).map(|i| unflatten(i, extent)).collect();
    let n = prepared.first().map_or(0, Vec::len);
    // Per finest sample, the sum of the levels built so far along its path.
    let mut above = vec![vec![0.0f32; n]; prepared.len()];
    block.levels.clear();
    for counts in level_counts {
        let images: usize = counts.iter().map(|&c| c as usize).product();
        let mut means = vec![vec![0.0f64; n]; images];
        let mut members = vec![Vec::new(); images];
        for (s, local) in locals.iter().enumerate() {
            let m = level_image_index(counts, local, extent);
            members[m].push(s);
            means[m].iter_mut().zip(&prepared[s]).for_each(|(a, v)| *a += *v as f64);
        }
        let mut level = Level { counts: counts.clone(), images: Vec::with_capacity(images) };
        for (m, sum) in means.iter().enumerate() {
            let first = *members[m].first().ok_or_else(|| {
                Error::Request(format!("level {counts:?} image {m} covers no sample"))
            })?;
            let k = members[m].len() as f64;
            let residual: Vec<f32> =
                sum.iter().zip(&above[first]).map(|(s, a)| (s / k) as f32 - a).collect();
            for &s in &members[m] {
                above[s].iter_mut().zip(&residual).for_each(|(a, r)| *a += r);
            }
            let bytes = pis_codec::encode(codec, &planes, &residual)
                .map_err(|e| Error::Request(e.to_string()))?;
            level.images.push(Codestream { codec, bytes });
        }
        block.levels.push(level);
    }
    Ok(block)
}

fn unflatten(mut i: usize, extent: &[u32]) -> Vec<u32> {
    let mut out = vec![0; extent.len()];
    for k in (0..extent.len()).rev() {
        out[k] = (i % extent[k] as usize) as u32;
        i /= extent[k] as usize;
    }
    out
}

/// Rotation about +Y by `deg` degrees, then a translation, as a row-major 3×4 matrix.
pub fn rotate_y_translate(deg: f32, t: [f32; 3]) -> [f32; 12] {
    let (s, c) = deg.to_radians().sin_cos();
    [c, 0.0, s, t[0], 0.0, 1.0, 0.0, t[1], -s, 0.0, c, t[2]]
}

/// A camera orbiting the origin at distance `r`, `deg` degrees about +Y, looking at it.
fn orbit_camera(deg: f32, r: f32) -> Camera {
    let (s, c) = deg.to_radians().sin_cos();
    Camera {
        world_from_camera: rotate_y_translate(deg, [r * s, 0.0, r * c]),
        yfov: 0.8,
        znear: 0.1,
        zfar: 100.0,
    }
}

/// The spec's worked example: one dimension of 2 view samples, one diffuse quad with one
/// 2×2 raw texture that does not vary.
pub fn minimal() -> Result<Container, Error> {
    let space = ParameterSpace {
        dims: vec![Dimension {
            name: "view".into(),
            kind: DimensionKind::View,
            periodic: false,
            unit: "deg".into(),
            block_size: 8,
            values: vec![0.0, 10.0],
        }],
    };
    let cameras = CameraTable {
        width: 4,
        height: 3,
        depends_on: DepMask::of(&[0]),
        cameras: vec![orbit_camera(0.0, 2.0), orbit_camera(10.0, 2.0)],
    };
    let mesh = Mesh {
        positions: vec![[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]],
        normals: None,
        texcoords: Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]),
        indices: vec![0, 1, 2, 0, 2, 3],
        hull_triangles: 0,
    };
    let layer = surface_layer(LayerKind::Diffuse, 0, DepMask::NONE, 1.0);
    let block = Block {
        width: 2,
        height: 2,
        placement: Placement::surface([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        levels: vec![],
    };
    let texels = vec![1.0, 0.5, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5, 0.5, 0.5];
    let block = encode_block(&layer, block, &[], &[vec![]], &[texels], CodecId::Raw)?;
    let object = Object {
        name: "quad".into(),
        role: ObjectRole::Diffuse,
        shading: Shading::default(),
        stagger: vec![0],
        transforms: TransformTable::fixed(IDENTITY_3X4),
        mesh,
        layers: vec![Layer { blocks: vec![block], ..layer }],
    };
    Ok(Container {
        space,
        cameras,
        objects: vec![object],
        provenance: Some(Provenance {
            tool: "pis-format example".into(),
            source: String::new(),
            raw_image_bytes: 2 * 4 * 3 * 3,
            settings: vec![("codec".into(), "raw".into())],
        }),
    })
}

fn surface_layer(kind: LayerKind, order: u8, depends_on: DepMask, gamma: f32) -> Layer<Codestream> {
    Layer {
        kind,
        mapping: Mapping::Surface,
        channels: 3,
        mip_mode: MipMode::Decimated,
        term: Term::Surface,
        order,
        combine: Combine::Add,
        basis: 0,
        gamma,
        depends_on,
        blocks: vec![],
    }
}

/// A UV sphere of radius `r` (longitude × latitude segments) with normals and texcoords.
pub fn uv_sphere(r: f32, lon: u32, lat: u32) -> Mesh {
    let mut m = Mesh { normals: Some(vec![]), texcoords: Some(vec![]), ..Default::default() };
    for j in 0..=lat {
        let v = j as f32 / lat as f32;
        let theta = v * std::f32::consts::PI;
        for i in 0..=lon {
            let u = i as f32 / lon as f32;
            let phi = u * std::f32::consts::TAU;
            let n = [theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()];
            m.positions.push([n[0] * r, n[1] * r, n[2] * r]);
            m.normals.as_mut().expect("set above").push(n);
            m.texcoords.as_mut().expect("set above").push([u, v]);
        }
    }
    for j in 0..lat {
        for i in 0..lon {
            let a = j * (lon + 1) + i;
            let b = a + lon + 1;
            m.indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

/// `samples/tiny.pis`: a 2×2 space (view × light), one reflective sphere with a diffuse
/// texture that varies with the light (a 2-level pyramid, gamma 2.2) and one distant sphere
/// shell that varies with the view (MIP chain stored), blocks staggered along the view,
/// lossless codec.
pub fn tiny() -> Result<Container, Error> {
    let dim = |name: &str, kind, unit: &str, values: Vec<f32>| Dimension {
        name: name.into(),
        kind,
        periodic: false,
        unit: unit.into(),
        block_size: 2,
        values,
    };
    let space = ParameterSpace {
        dims: vec![
            dim("view", DimensionKind::View, "deg", vec![0.0, 5.0]),
            dim("light", DimensionKind::Light, "", vec![0.0, 1.0]),
        ],
    };
    let cameras = CameraTable {
        width: 32,
        height: 24,
        depends_on: DepMask::of(&[0]),
        cameras: vec![orbit_camera(0.0, 3.0), orbit_camera(5.0, 3.0)],
    };
    let stagger = vec![1, 0];
    let codec = CodecId::Lossless;

    // Diffuse: 8×8 checker scaled by the light sample; one block over `light` (offset 0).
    let diffuse = surface_layer(LayerKind::Diffuse, 0, DepMask::of(&[1]), 2.2);
    let (w, h) = (8u32, 8u32);
    let texture = |light: u32| -> Vec<f32> {
        let mut t = Vec::with_capacity((w * h * 3) as usize);
        for y in 0..h {
            for x in 0..w {
                let check = if (x / 2 + y / 2) % 2 == 0 { 0.8 } else { 0.2 };
                let s = 0.5 + 0.5 * light as f32;
                t.extend([check * s, check * s * 0.9, check * s * 0.7]);
            }
        }
        t
    };
    let block = Block {
        width: w,
        height: h,
        placement: Placement::surface([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        levels: vec![],
    };
    let block =
        encode_block(&diffuse, block, &[2], &[vec![1], vec![2]], &[texture(0), texture(1)], codec)?;
    let diffuse = Layer { blocks: vec![block], ..diffuse };

    // Distant shell: a sphere of radius 4, 4×4 faces with their MIP chain, over `view`,
    // whose block origin is staggered by 1: two blocks of one sample each.
    let shell = Layer {
        kind: LayerKind::EnvDistant,
        mapping: Mapping::Shell,
        channels: 3,
        mip_mode: MipMode::Stored,
        term: Term::Reflection,
        order: 0,
        combine: Combine::Over,
        basis: 0,
        gamma: 1.0,
        depends_on: DepMask::of(&[0]),
        blocks: vec![],
    };
    let grid = BlockGrid::new(&space, shell.depends_on, &stagger);
    let mut blocks = Vec::new();
    for b in 0..grid.block_count() as usize {
        let view = b as u32; // extent 1 each: block b holds view sample b
        let block = Block {
            width: 4,
            height: 4,
            placement: Placement::Shell {
                shape: ShellShape::Sphere,
                origin: [0.0; 3],
                params: [4.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                lookups: 1,
            },
            levels: vec![],
        };
        let layout = LevelLayout::of(&shell, &block);
        let mut values = Vec::new();
        for (pi, p) in layout.planes().iter().enumerate() {
            let face = pi as u32 / layout.mips;
            for y in 0..p.height {
                for x in 0..p.width {
                    let g = (x + y) as f32 / 8.0;
                    values.extend([0.1 * face as f32 + g, 0.3 + 0.1 * view as f32, 1.0 - g]);
                }
            }
        }
        blocks.push(encode_block(&shell, block, &grid.extent(b), &[vec![1]], &[values], codec)?);
    }
    let shell = Layer { blocks, ..shell };

    let object = Object {
        name: "ball".into(),
        role: ObjectRole::Reflective,
        shading: Shading { f0: [0.9, 0.85, 0.8], ior: 1.5, absorption: [0.0; 3] },
        stagger,
        transforms: TransformTable::fixed(IDENTITY_3X4),
        mesh: uv_sphere(1.0, 8, 6),
        layers: vec![diffuse, shell],
    };
    Ok(Container {
        space,
        cameras,
        objects: vec![object],
        provenance: Some(Provenance {
            tool: format!("pis-format {}", env!("CARGO_PKG_VERSION")),
            source: "generated by pis_format::samples::tiny".into(),
            raw_image_bytes: 4 * 32 * 24 * 3,
            settings: vec![("codec".into(), "lossless".into()), ("block".into(), "2x2".into())],
        }),
    })
}

/// A lossless master for `c` (SPEC.md 6.7): every layer sample's texture as the container
/// decodes it, screen area 1 for every object. With `tiny()`, the sample of a file that
/// carries one.
pub fn master_of(c: &Container) -> Result<Vec<crate::Master>, Error> {
    let r = crate::PisReader::from_bytes(crate::to_bytes(c)?)?;
    c.objects
        .iter()
        .enumerate()
        .map(|(oi, o)| {
            let textures = o
                .layers
                .iter()
                .enumerate()
                .map(|(li, l)| {
                    (0..c.space.table_len(l.depends_on))
                        .map(|s| Ok(r.texture(oi, li, &crate::master::sample_point(c, l, s))?.data))
                        .collect::<Result<Vec<_>, Error>>()
                })
                .collect::<Result<Vec<_>, Error>>()?;
            crate::Master::encode(c, oi, 1.0, &textures, None)
        })
        .collect()
}
