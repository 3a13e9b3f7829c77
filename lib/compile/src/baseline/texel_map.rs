//! Texel centres mapped back onto the object: each sample (s, t) of a texture grid is
//! located in the mesh's texture-space triangles (after the block's affine transform); its
//! barycentrics give the object-space point, and the vertex transform its screen position.
//! Where several triangles share the same (s, t) the one nearest the camera is kept.

use glam::{Vec3, Vec4};

use crate::transform::{to_framebuffer, DrawMesh, TextureTransform, Viewport};

/// Where one texture sample lies on the object and on the screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelPoint {
    pub object: Vec3,
    pub clip: Vec4,
    /// Framebuffer position in pixels (y down); meaningful when `clip.w > 0`.
    pub screen: [f32; 2],
}

/// Maps the centres of a `width × height` sample grid over (s, t) ∈ [0, 1]² to the object.
pub fn map_texels(
    mesh: &DrawMesh,
    transform: &TextureTransform,
    viewport: Viewport,
    width: u32,
    height: u32,
) -> Vec<Option<TexelPoint>> {
    let mut out: Vec<Option<TexelPoint>> = vec![None; width as usize * height as usize];
    let (fw, fh) = (width as f64, height as f64);
    for tri in mesh.indices.chunks_exact(3) {
        let idx = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
        if idx.iter().any(|&i| i >= mesh.positions.len() || i >= mesh.uvs.len()) {
            continue;
        }
        // triangle in sample-grid coordinates
        let st: Vec<[f64; 2]> = idx
            .iter()
            .map(|&i| {
                let p = transform.texcoord(mesh.uvs[i]);
                [p[0] as f64 * fw, p[1] as f64 * fh]
            })
            .collect();
        let area = (st[1][0] - st[0][0]) * (st[2][1] - st[0][1])
            - (st[1][1] - st[0][1]) * (st[2][0] - st[0][0]);
        if area.abs() < 1e-12 {
            continue;
        }
        let lo = |c: usize| st.iter().map(|p| p[c]).fold(f64::INFINITY, f64::min);
        let hi = |c: usize| st.iter().map(|p| p[c]).fold(f64::NEG_INFINITY, f64::max);
        let x0 = (lo(0) - 0.5).ceil().max(0.0) as i64;
        let x1 = ((hi(0) - 0.5).floor() as i64).min(width as i64 - 1);
        let y0 = (lo(1) - 0.5).ceil().max(0.0) as i64;
        let y1 = ((hi(1) - 0.5).floor() as i64).min(height as i64 - 1);
        let pos = idx.map(|i| Vec3::from(mesh.positions[i]));
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let e = |a: [f64; 2], b: [f64; 2]| {
                    (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])
                };
                let l = [e(st[1], st[2]) / area, e(st[2], st[0]) / area, e(st[0], st[1]) / area];
                if l.iter().any(|&v| v < -1e-9) {
                    continue;
                }
                let object = pos[0] * l[0] as f32 + pos[1] * l[1] as f32 + pos[2] * l[2] as f32;
                let clip = mesh.clip_from_object * object.extend(1.0);
                let k = y as usize * width as usize + x as usize;
                let nearer = match &out[k] {
                    None => true,
                    Some(old) => {
                        clip.w > 0.0
                            && (old.clip.w <= 0.0 || clip.z / clip.w < old.clip.z / old.clip.w)
                    }
                };
                if nearer {
                    let f =
                        if clip.w > 0.0 { to_framebuffer(clip, viewport) } else { [f32::NAN; 3] };
                    out[k] = Some(TexelPoint { object, clip, screen: [f[0], f[1]] });
                }
            }
        }
    }
    out
}
