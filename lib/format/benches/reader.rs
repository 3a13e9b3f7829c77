//! Container reading speed on a synthetic file shaped like a packed object: one 8×8 block of
//! a 2D parameter space, 256×256 RGB textures, a 4-level Laplacian pyramid (1, 2×2, 4×4, 8×8),
//! lossless codec. Measures: open (header, table, metadata, rules), cold decode of one
//! parameter sample (4 codestreams), and full validation.
//! Run: cargo bench -p pis-format

use std::time::Instant;

use pis_format::samples::{encode_block, rotate_y_translate, uv_sphere};
use pis_format::*;

fn container() -> Container {
    let dim = |name: &str, kind| Dimension {
        name: name.into(),
        kind,
        periodic: false,
        unit: String::new(),
        block_size: 8,
        values: (0..8).map(|i| i as f32).collect(),
    };
    let space = ParameterSpace {
        dims: vec![dim("light", DimensionKind::Light), dim("view", DimensionKind::View)],
    };
    let cameras = CameraTable {
        width: 640,
        height: 480,
        depends_on: DepMask::of(&[1]),
        cameras: (0..8)
            .map(|i| Camera {
                world_from_camera: rotate_y_translate(i as f32, [0.0, 0.0, 3.0]),
                yfov: 0.8,
                znear: 0.1,
                zfar: 100.0,
            })
            .collect(),
    };
    let layer = Layer {
        kind: LayerKind::Specular,
        mapping: Mapping::Surface,
        channels: 3,
        mip_mode: MipMode::Decimated,
        term: Term::Surface,
        order: 0,
        combine: Combine::Add,
        basis: 0,
        gamma: 2.2,
        depends_on: DepMask::of(&[0, 1]),
        blocks: vec![],
    };
    let (w, h) = (256u32, 256u32);
    let samples: Vec<Vec<f32>> = (0..64)
        .map(|s| {
            let (a, b) = ((s / 8) as f32, (s % 8) as f32);
            let mut t = Vec::with_capacity((w * h * 3) as usize);
            for y in 0..h {
                for x in 0..w {
                    let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
                    let hl = (-((u - 0.3 - 0.03 * b).powi(2) + (v - 0.5 - 0.02 * a).powi(2))
                        * 40.0)
                        .exp();
                    t.extend([0.2 + hl, 0.25 + 0.9 * hl, 0.3 + 0.8 * hl]);
                }
            }
            t
        })
        .collect();
    let block = Block {
        width: w,
        height: h,
        placement: Placement::surface([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        levels: vec![],
    };
    let levels = vec![vec![1, 1], vec![2, 2], vec![4, 4], vec![8, 8]];
    let block =
        encode_block(&layer, block, &[8, 8], &levels, &samples, CodecId::Lossless).expect("encode");
    Container {
        space,
        cameras,
        objects: vec![Object {
            name: "vase".into(),
            role: ObjectRole::Diffuse,
            shading: Shading::default(),
            stagger: vec![0, 0],
            transforms: TransformTable::fixed(IDENTITY_3X4),
            mesh: uv_sphere(1.0, 32, 16),
            layers: vec![Layer { blocks: vec![block], ..layer }],
        }],
        provenance: Some(Provenance { raw_image_bytes: 64 * 640 * 480 * 3, ..Default::default() }),
    }
}

fn main() {
    let c = container();
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bench.pis");
    let size = write(&path, &c).expect("write");
    println!(
        "file: {} bytes, 64 samples of a 256x256 RGB texture, 4 pyramid levels, lossless",
        size
    );

    let reps = 200;
    let t = Instant::now();
    for _ in 0..reps {
        PisReader::open(&path).expect("open");
    }
    println!(
        "open (header, table, metadata, all rules): {:.3} ms",
        t.elapsed().as_secs_f64() * 1e3 / reps as f64
    );

    let t = Instant::now();
    let mut reads = 0;
    for s in 0..64u32 {
        let r = PisReader::open(&path).expect("open");
        r.texture(0, 0, &[s / 8, s % 8]).expect("texture");
        reads += r.stats().codestreams;
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / 64.0;
    println!(
        "cold decode of one sample (open + {} codestreams): {ms:.2} ms, {:.0} Mtexel/s",
        reads / 64,
        (256.0 * 256.0) / (ms * 1e3)
    );

    let t = Instant::now();
    let v = validate_file(&path);
    assert!(v.is_valid());
    println!(
        "validate (every checksum, every codestream decoded): {:.1} ms",
        t.elapsed().as_secs_f64() * 1e3
    );
}
