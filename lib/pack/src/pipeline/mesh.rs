//! An object's mesh and its texture placement (thesis 3.2): the primitives merged, the
//! texture coordinates the file's mesh carries (the atlas), and the placement over one
//! parameter block's views (branch cuts, affine map, used size, wrapping).

use anyhow::Result;
use glam::Vec3;
use pis_compile::texcoord::{
    charts::{separate_overlapping_charts, unfold_charts},
    optimize_placement, rechart, ObjectMesh, TexcoordSettings, ViewGeometry,
};
use pis_compile::{Address, Filter, Sampler, TextureLayout, TextureTransform};
use pis_scene::{Frame, Scene};

/// One object's mesh, all primitives merged, in object space.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    /// What [`rechart::rechart`] did to texture coordinates that could not hold a texture,
    /// for the report; `None` where the mesh's own were kept.
    pub recharted: Option<String>,
    /// Some material of the object lets light through part of its surface (glTF alpha mode
    /// MASK or BLEND): the object is stored with its opacity and the player composites it
    /// over the opaque surfaces behind it (SPEC.md 9).
    pub translucent: bool,
}

/// Object `o`'s primitives merged into one mesh, in primitive order, its folded charts cut
/// apart ([`unfold_charts`]: vertices copied, triangles kept in order) and its triangles of
/// degenerate texture coordinates charted again ([`rechart::rechart`]).
pub fn merged_mesh(scene: &Scene, o: usize) -> Mesh {
    let translucent = is_translucent(scene, o);
    let mut m = Mesh {
        positions: vec![],
        normals: vec![],
        uvs: vec![],
        indices: vec![],
        recharted: None,
        translucent,
    };
    for p in &scene.objects[o].primitives {
        let base = m.positions.len() as u32;
        m.positions.extend(p.positions.iter().map(|v| v.to_array()));
        // The scene gives one unit normal per vertex; a primitive built otherwise gets its
        // triangles' normals.
        if p.normals.len() == p.positions.len() {
            m.normals.extend(p.normals.iter().map(|v| v.to_array()));
        } else {
            m.normals.extend(vertex_normals(&p.positions, &p.indices));
        }
        if p.uvs.len() == p.positions.len() {
            m.uvs.extend(p.uvs.iter().map(|v| v.to_array()));
        } else {
            m.uvs.extend(std::iter::repeat_n([0.0, 0.0], p.positions.len()));
        }
        m.indices.extend(p.indices.iter().map(|i| i + base));
    }
    // A chart folded onto itself (mirrored coordinates) is cut where it turns over, so that
    // its halves can get texels of their own.
    let uvs: Vec<glam::Vec2> = m.uvs.iter().map(|u| glam::Vec2::from(*u)).collect();
    if let Some(u) = unfold_charts(&uvs, &m.indices) {
        for &v in &u.copies {
            let v = v as usize;
            m.positions.push(m.positions[v]);
            m.normals.push(m.normals[v]);
            m.uvs.push(m.uvs[v]);
        }
        m.indices = u.indices;
    }
    recharted(m)
}

/// Whether some material of object `o` lets light through part of its surface
/// ([`Mesh::translucent`]).
pub fn is_translucent(scene: &Scene, o: usize) -> bool {
    scene.objects[o]
        .primitives
        .iter()
        .any(|p| scene.materials.get(p.material).is_some_and(pis_trace::material::has_holes))
}

/// The triangles of mesh `k` that hide object `o` from the camera: none where `k` is
/// translucent and `o` is not, since the player draws the opaque surfaces first and
/// composites the translucent ones over them (SPEC.md 9).
pub fn occluding_indices(meshes: &[Mesh], o: usize, k: usize) -> &[u32] {
    if k != o && meshes[k].translucent && !meshes[o].translucent {
        &[]
    } else {
        &meshes[k].indices
    }
}

/// `m` with its triangles of degenerate texture coordinates charted again (vertices copied,
/// triangles kept in order), and a note saying so.
fn recharted(mut m: Mesh) -> Mesh {
    let positions: Vec<Vec3> = m.positions.iter().map(|p| Vec3::from(*p)).collect();
    let uvs: Vec<glam::Vec2> = m.uvs.iter().map(|u| glam::Vec2::from(*u)).collect();
    let Some(r) = rechart::rechart(&positions, &uvs, &m.indices) else { return m };
    for &v in &r.copies {
        let v = v as usize;
        m.positions.push(m.positions[v]);
        m.normals.push(m.normals[v]);
    }
    m.recharted = Some(r.describe(m.indices.len() / 3));
    m.uvs = r.uvs.iter().map(|u| u.to_array()).collect();
    m.indices = r.indices;
    m
}

/// Area-weighted vertex normals of a triangle list (+Y where a vertex has no area).
fn vertex_normals(positions: &[Vec3], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        if let (Some(&pa), Some(&pb), Some(&pc)) =
            (positions.get(a), positions.get(b), positions.get(c))
        {
            let f = (pb - pa).cross(pc - pa);
            [a, b, c].iter().for_each(|&v| n[v] += f);
        }
    }
    n.iter().map(|v| v.normalize_or(Vec3::Y).to_array()).collect()
}

/// Whether the texture wraps along u / v: the mesh has a seam, vertices at u = 0 and u = 1
/// (v = 0 and v = 1) at the same position.
pub fn seam_wraps(mesh: &Mesh) -> [bool; 2] {
    let mut out = [false; 2];
    for (dim, flag) in out.iter_mut().enumerate() {
        let key = |p: [f32; 3]| p.map(|c| (c * 1e4).round() as i64);
        let lo: std::collections::BTreeSet<_> = mesh
            .positions
            .iter()
            .zip(&mesh.uvs)
            .filter(|(_, uv)| uv[dim].abs() < 1e-4)
            .map(|(p, _)| key(*p))
            .collect();
        let matches = mesh
            .positions
            .iter()
            .zip(&mesh.uvs)
            .filter(|(p, uv)| (uv[dim] - 1.0).abs() < 1e-4 && lo.contains(&key(**p)))
            .count();
        *flag = matches >= 2;
    }
    out
}

/// An object's texture coordinates as its mesh carries them in the file, and which of them
/// are periodic.
pub struct Atlas {
    pub uvs: Vec<[f32; 2]>,
    pub wrap: [bool; 2],
}

/// The mesh of object `o` as the views of `frames` see it (clip-space vertices).
fn view_geometry(frames: &[&Frame], res: (u32, u32), o: usize, mesh: &Mesh) -> Vec<ViewGeometry> {
    frames
        .iter()
        .map(|frame| {
            let proj = pis_trace::camera::projection_matrix(&frame.camera, res);
            let clip_from_object = proj
                * frame.camera.world_from_camera.inverse()
                * frame.instances[o].world_from_object;
            ViewGeometry {
                clip: mesh
                    .positions
                    .iter()
                    .map(|p| clip_from_object * Vec3::from(*p).extend(1.0))
                    .collect(),
                width: res.0,
                height: res.1,
            }
        })
        .collect()
}

/// The object's texture coordinates over the views of `frames`: visible parts sharing (u, v)
/// (a room's walls each mapped onto the whole wallpaper) laid out side by side, one texel per
/// surface point ([`separate_overlapping_charts`]); else the mesh's own, periodic where the
/// mesh has a seam.
pub fn atlas(frames: &[&Frame], res: (u32, u32), o: usize, mesh: &Mesh) -> Atlas {
    let views = view_geometry(frames, res, o, mesh);
    let uvs: Vec<glam::Vec2> = mesh.uvs.iter().map(|u| glam::Vec2::from(*u)).collect();
    match separate_overlapping_charts(&uvs, &mesh.indices, &views) {
        Some(atlas) => {
            Atlas { uvs: atlas.iter().map(|uv| uv.to_array()).collect(), wrap: [false, false] }
        }
        None => Atlas { uvs: mesh.uvs.clone(), wrap: seam_wraps(mesh) },
    }
}

/// An object's texture placement for the views of one parameter block (thesis 3.2): branch
/// cuts and affine map, used size with its MIP chain, wrapping, the reduction applied.
#[derive(Clone, Debug)]
pub struct Placed {
    pub transform: TextureTransform,
    pub layout: TextureLayout,
    pub repeat: [bool; 2],
    pub reduction: f64,
}

impl Placed {
    /// Whether textures placed by `self` and `other` are drawn alike (the same texture
    /// transform, size and wrapping).
    pub fn same(&self, other: &Placed) -> bool {
        self.transform == other.transform
            && self.layout == other.layout
            && self.repeat == other.repeat
    }
}

/// Branch cuts, the most isometric map, the stretch limit, the bounding rectangle and the
/// used resolution of object `o` with the texture coordinates of `atlas`, over the views of
/// `frames` (one parameter block's).
#[allow(clippy::too_many_arguments)]
pub fn place_in(
    scene: &Scene,
    frames: &[&Frame],
    res: (u32, u32),
    o: usize,
    mesh: &Mesh,
    atlas: &Atlas,
    max_texture: u32,
    reduction: f64,
    texels_per_pixel: Option<f64>,
) -> Result<Placed> {
    let views = view_geometry(frames, res, o, mesh);
    let uvs: Vec<glam::Vec2> = atlas.uvs.iter().map(|u| glam::Vec2::from(*u)).collect();
    let name = &scene.objects[o].name;
    let om = ObjectMesh { name, uvs: &uvs, indices: &mesh.indices, wrap: atlas.wrap };
    let settings = TexcoordSettings {
        max_size: max_texture,
        reduction,
        texels_per_pixel,
        ..TexcoordSettings::default()
    };
    let pl = optimize_placement(&om, &views, &settings)?;
    Ok(Placed {
        // A cut rounded up to 1 in f32 is the cut at 0.
        transform: TextureTransform {
            values: pl.affine,
            cut: pl.branch_cut.map(|c| c.map(|c| if (c as f32) < 1.0 { c as f32 } else { 0.0 })),
        },
        layout: TextureLayout::full(pl.width, pl.height),
        repeat: pl.repeat,
        reduction: pl.reduction,
    })
}

/// The sampler of a texture drawn with `filter`, repeating where `repeat` says.
pub fn sampler(filter: Filter, repeat: [bool; 2]) -> Sampler {
    Sampler {
        filter,
        address: repeat.map(|r| if r { Address::Repeat } else { Address::ClampToEdge }),
    }
}
