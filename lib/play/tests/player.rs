//! The player on samples/tiny.pis (a reflective ball: a diffuse texture over the light and a
//! distant shell over the view) and the GPU MIP chain: a frame reads exactly the codestreams
//! on the pyramid paths of the samples it draws, surface layers' and shells' (fewer when
//! level images are cached or textures resident), multilinear blending between two light
//! samples is the weighted sum of their frames, and the GPU's MIP decimation equals
//! pis-format's.

mod common;

use std::path::PathBuf;
use std::sync::Arc;

use common::*;
use pis_format::mip::{decimate, mip_size};
use pis_play::decode::TextureImage;
use pis_play::mip::{read_levels, MipBuilder};
use pis_play::{Blend, CameraChoice, FrameRequest, Player, PlayerOptions, Rebuild};

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

fn tiny() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/tiny.pis")
}

/// Distinct codestreams on the pyramid paths of every layer at `points`.
fn path_streams(player: &Player, points: &[Vec<u32>]) -> Vec<(u32, u64)> {
    let r = player.reader();
    let mut out = Vec::new();
    for (oi, o) in r.container().objects.iter().enumerate() {
        for li in 0..o.layers.len() {
            for p in points {
                for s in r.texture_path(oi, li, p).unwrap().1 {
                    if !out.contains(&(s.chunk, s.offset)) {
                        out.push((s.chunk, s.offset));
                    }
                }
            }
        }
    }
    out
}

fn at(player: &Player, samples: &[u32]) -> FrameRequest {
    let point =
        player.dimensions().iter().zip(samples).map(|(d, &s)| d.values[s as usize]).collect();
    FrameRequest { point, camera: CameraChoice::Sample }
}

#[test]
fn a_frame_reads_only_the_codestreams_of_its_pyramid_paths() {
    let Some(gpu) = gpu_or_skip("a_frame_reads_only_the_codestreams_of_its_pyramid_paths") else {
        return;
    };
    // One sample per pixel: alpha is 1 exactly where the object index is drawn.
    let mut player = Player::open(
        Arc::new(gpu),
        &tiny(),
        PlayerOptions { workers: 2, msaa: 1, ..Default::default() },
    )
    .unwrap();
    let size = player.image_size();
    // tiny.pis: dimensions (view, light); the surface layer varies with light, the shell
    // with the view.
    let first = vec![0, 0];
    let (img, ids, s) = player.render_ids(&at(&player, &first), size).unwrap();
    let want = path_streams(&player, std::slice::from_ref(&first));
    assert!(!want.is_empty());
    assert_eq!((s.surface_draws, s.shell_draws), (1, 1));
    assert_eq!(s.codestreams_read, want.len() as u64, "first frame reads its pyramid path");
    assert_eq!(player.reader().stats().codestreams, want.len() as u64);
    assert_eq!((s.cache_misses, s.cache_hits), (want.len() as u64, 0));
    assert!(s.upload_bytes > 0 && s.cache_bytes > 0);
    let covered = ids.iter().filter(|&&i| i == 0).count();
    assert!(covered > 20, "the ball covers {covered} pixels");
    assert!(ids.iter().all(|&i| i == 0 || i == u32::MAX));
    for (k, &i) in ids.iter().enumerate() {
        let a = img.rgba[k * 4 + 3];
        assert_eq!(a, if i == 0 { 1.0 } else { 0.0 }, "alpha marks the drawn pixels");
    }
    // Another view, same light: the diffuse texture is the same; only the shell of the new
    // view (another block) is read.
    let view = vec![1, 0];
    let (_, s) = player.render_image(&at(&player, &view), size).unwrap();
    let seen = path_streams(&player, &[first.clone(), view.clone()]);
    assert!(seen.len() > want.len());
    assert_eq!(s.codestreams_read, (seen.len() - want.len()) as u64, "only the new view's shell");
    // Another light: only the level images not already cached.
    let second = vec![1, 1];
    let (_, s) = player.render_image(&at(&player, &second), size).unwrap();
    let all = path_streams(&player, &[first, view, second]);
    assert_eq!(
        s.codestreams_read,
        (all.len() - seen.len()) as u64,
        "shared pyramid levels come from the cache"
    );
    assert!(s.cache_hits >= 1, "the top level is shared");
    assert_eq!(player.reader().stats().codestreams, all.len() as u64);
}

/// Decoding ahead: told of the next frame, the player prepares its textures while the
/// current frame draws — level images decoded, and where the workers rebuild textures, the
/// textures rebuilt — so the next frame waits on nothing and draws the same image as a
/// player that decoded when asked.
#[test]
fn the_next_frame_prepared_ahead_waits_on_nothing_and_draws_the_same() {
    let name = "the_next_frame_prepared_ahead_waits_on_nothing_and_draws_the_same";
    let Some(gpu) = gpu_or_skip(name) else { return };
    let gpu = Arc::new(gpu);
    for rebuild in [Rebuild::Workers, Rebuild::Gpu] {
        let options = PlayerOptions { workers: 1, msaa: 1, rebuild, ..Default::default() };
        let mut ahead = Player::open(gpu.clone(), &tiny(), options.clone()).unwrap();
        let mut asked = Player::open(gpu.clone(), &tiny(), options).unwrap();
        let size = ahead.image_size();
        let (first, next) = (at(&ahead, &[0, 0]), at(&ahead, &[1, 1]));
        ahead.prefetch(std::slice::from_ref(&next));
        let (_, s) = ahead.render_image(&first, size).unwrap();
        assert!(s.decode_waits > 0, "{rebuild:?}: the first frame decodes when it asks");
        ahead.prefetch(&[]);
        let (got, s) = ahead.render_image(&next, size).unwrap();
        assert_eq!(s.decode_waits, 0, "{rebuild:?}: the next frame's images were decoded ahead");
        assert!(s.prefetched > 0 && s.cache_misses == 0, "{rebuild:?}: {s:?}");
        // tiny.pis's next frame draws two textures, neither on the GPU yet.
        let rebuilt_ahead = if rebuild == Rebuild::Workers { 2 } else { 0 };
        assert_eq!(s.rebuilt_ahead, rebuilt_ahead, "{rebuild:?}: {s:?}");
        asked.render_image(&first, size).unwrap();
        let (want, s) = asked.render_image(&next, size).unwrap();
        assert!(s.decode_waits > 0 && s.prefetched == 0);
        assert_eq!(got.rgba, want.rgba, "{rebuild:?}: prepared ahead or when asked, the same");
    }
}

/// A level image used only through a texture rebuilt ahead is used by the frame that draws
/// that texture: its lifetime counts from then, so a motion that comes back to a sample
/// within the lifetime finds its level images decoded.
#[test]
fn level_images_of_textures_rebuilt_ahead_live_from_the_frame_that_draws_them() {
    let name = "level_images_of_textures_rebuilt_ahead_live_from_the_frame_that_draws_them";
    let Some(gpu) = gpu_or_skip(name) else { return };
    // Leaves live 3 frames since their last use; every point of tiny.pis (view × light) in
    // turn, each texture drawn two frames in four, the next frame's textures prepared ahead.
    let options = PlayerOptions {
        workers: 1,
        msaa: 1,
        rebuild: Rebuild::Workers,
        lifetime_a: 3,
        ..Default::default()
    };
    let mut player = Player::open(Arc::new(gpu), &tiny(), options).unwrap();
    let size = player.image_size();
    let cycle = [[0, 0], [1, 0], [1, 1], [0, 1]];
    let mut reads = Vec::new();
    let mut ahead = 0;
    for f in 0..16 {
        let next = at(&player, &cycle[(f + 1) % 4]);
        player.prefetch(std::slice::from_ref(&next));
        let (_, s) = player.render_image(&at(&player, &cycle[f % 4]), size).unwrap();
        ahead += s.rebuilt_ahead;
        reads.push(player.reader().stats().codestreams);
    }
    // Consecutive points share one of their two textures; the other, never drawn the frame
    // before, is rebuilt ahead (the frame waits for the rebuild it asked for, if running).
    assert_eq!(ahead, 15, "textures rebuilt ahead");
    assert_eq!(reads[15], reads[3], "codestreams read after each frame: {reads:?}");
}

/// The GPU's rebuild and the workers' draw the same frames (every texture of tiny.pis: a
/// surface texture and a shell's cube map with stored MIP levels).
#[test]
fn frames_rebuilt_on_the_gpu_equal_frames_rebuilt_on_the_workers() {
    let name = "frames_rebuilt_on_the_gpu_equal_frames_rebuilt_on_the_workers";
    let Some(gpu) = gpu_or_skip(name) else { return };
    let gpu = Arc::new(gpu);
    let open = |rebuild| {
        let options = PlayerOptions { workers: 1, msaa: 1, rebuild, ..Default::default() };
        Player::open(gpu.clone(), &tiny(), options).unwrap()
    };
    let (mut on_gpu, mut workers) = (open(Rebuild::Gpu), open(Rebuild::Workers));
    assert_eq!((on_gpu.rebuild(), workers.rebuild()), (Rebuild::Gpu, Rebuild::Workers));
    let size = on_gpu.image_size();
    for samples in [[0, 0], [1, 0], [1, 1]] {
        let (a, _) = on_gpu.render_image(&at(&on_gpu, &samples), size).unwrap();
        let (b, _) = workers.render_image(&at(&workers, &samples), size).unwrap();
        assert_eq!(a.rgba, b.rgba, "sample {samples:?}");
    }
}

#[test]
fn a_lossless_master_changes_no_frame_and_no_read() {
    let Some(gpu) = gpu_or_skip("a_lossless_master_changes_no_frame_and_no_read") else { return };
    let gpu = Arc::new(gpu);
    // tiny.pis again, with every layer sample's texture kept as a lossless master.
    let c = pis_format::PisReader::open(&tiny()).unwrap().load_all().unwrap();
    let masters = pis_format::samples::master_of(&c).unwrap();
    assert!(!masters.is_empty());
    let dir = tempfile::tempdir().unwrap();
    let with = dir.path().join("tiny-master.pis");
    pis_format::write_with_masters(&with, &c, &masters).unwrap();
    let mut plain =
        Player::open(gpu.clone(), &tiny(), PlayerOptions { workers: 1, ..Default::default() })
            .unwrap();
    let mut mastered =
        Player::open(gpu, &with, PlayerOptions { workers: 1, ..Default::default() }).unwrap();
    assert!(mastered.reader().has_master() && mastered.reader().master_bytes() > 0);
    let size = plain.image_size();
    for samples in [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]] {
        let (a, sa) = plain.render_image(&at(&plain, &samples), size).unwrap();
        let (b, sb) = mastered.render_image(&at(&mastered, &samples), size).unwrap();
        let differ = a.rgba.iter().zip(&b.rgba).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
        assert_eq!(differ, 0, "point {samples:?}: {differ} values differ");
        assert_eq!(
            (sa.codestreams_read, sa.cache_hits, sa.cache_misses, sa.cache_bytes),
            (sb.codestreams_read, sb.cache_hits, sb.cache_misses, sb.cache_bytes),
            "point {samples:?}"
        );
    }
    // Only level images were read: the same count and bytes as without the master.
    assert_eq!(plain.reader().stats(), mastered.reader().stats());
}

#[test]
fn multilinear_blend_is_the_weighted_sum_of_the_sample_frames() {
    let Some(gpu) = gpu_or_skip("multilinear_blend_is_the_weighted_sum_of_the_sample_frames")
    else {
        return;
    };
    let gpu = Arc::new(gpu);
    let mut player = Player::open(
        gpu,
        &tiny(),
        PlayerOptions { blend: Blend::Multilinear, workers: 1, ..Default::default() },
    )
    .unwrap();
    let size = player.image_size();
    let light = player.dimensions()[1].values.clone();
    let view = player.dimensions()[0].values[0];
    let camera = CameraChoice::Free(player.sample_camera(&[view, light[0]]));
    let frame = |p: &mut Player, l: f32| {
        p.render_image(&FrameRequest { point: vec![view, l], camera }, size).unwrap().0
    };
    let a = frame(&mut player, light[0]);
    let b = frame(&mut player, light[1]);
    let w = 0.3f32;
    let mid = frame(&mut player, light[0] + w * (light[1] - light[0]));
    let want: Vec<f32> = a
        .rgba
        .iter()
        .zip(&b.rgba)
        .enumerate()
        .map(|(k, (x, y))| if k % 4 == 3 { x.max(*y) } else { (1.0 - w) * x + w * y })
        .collect();
    let differ = a.rgba.iter().zip(&b.rgba).filter(|(x, y)| (*x - *y).abs() > 1e-3).count();
    assert!(differ > 10, "the two light samples differ ({differ} values)");
    let p = psnr(&mid.rgba, &want);
    assert!(p >= 50.0, "blend vs weighted sum: {p:.1} dB");
}

#[test]
fn gpu_mip_chain_equals_cpu_decimation() {
    let Some(gpu) = gpu_or_skip("gpu_mip_chain_equals_cpu_decimation") else { return };
    let mips = MipBuilder::new(&gpu);
    for (w, h) in [(13u32, 7u32), (16, 16), (1, 5), (37, 20)] {
        let values: Vec<f32> =
            (0..w * h * 4).map(|k| ((k as u64 * 2654435761u64 % 1000) as f32) / 997.0).collect();
        let layout = pis_compile::TextureLayout::full(w, h);
        let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
        let mut rgba = vec![0.0; (pw * ph * 4) as usize];
        for j in 0..ph {
            for i in 0..pw {
                let s = ((j.min(h - 1) * w + i.min(w - 1)) * 4) as usize;
                let d = ((j * pw + i) * 4) as usize;
                rgba[d..d + 4].copy_from_slice(&values[s..s + 4]);
            }
        }
        let image = TextureImage { width: w, height: h, padded_width: pw, padded_height: ph, rgba };
        let texture = mips.texture(&gpu, layout);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        mips.upload(&gpu, &texture, &image, &mut enc).unwrap();
        gpu.queue.submit([enc.finish()]);
        let levels = read_levels(&gpu, &texture).unwrap();
        assert_eq!(levels.len() as u32, layout.levels);
        // The CPU chain, padded like the GPU levels.
        let mut cpu = values.clone();
        for (m, (gw, gh, img)) in levels.iter().enumerate() {
            let m = m as u32;
            if m > 0 {
                let (sw, sh) = mip_size(w, h, m - 1);
                cpu = decimate(&cpu, sw, sh, 4);
            }
            let (uw, uh) = mip_size(w, h, m);
            let mut want = vec![0.0f32; img.len()];
            for j in 0..*gh {
                for i in 0..*gw {
                    let s = ((j.min(uh - 1) * uw + i.min(uw - 1)) * 4) as usize;
                    let d = ((j * gw + i) * 4) as usize;
                    want[d..d + 4].copy_from_slice(&cpu[s..s + 4]);
                }
            }
            if gpu.texture_format == wgpu::TextureFormat::Rgba32Float {
                assert_eq!(img, &want, "{w}x{h} level {m}: GPU and CPU decimation differ");
            } else {
                let p = psnr(img, &want);
                assert!(p >= 60.0, "{w}x{h} level {m}: {p:.1} dB");
            }
        }
    }
}

/// Multisampling on the player's path (samples/tiny.pis, a ball over nothing): object
/// indices are those at pixel centres either way; pixels partly covered (0 < alpha < 1) lie
/// on the silhouette only, there are about as many as the silhouette is long, and their
/// colour is no longer the single-sample one (the ball mixed with the empty background);
/// inside the ball, a pixel is
/// shaded at its centre by each triangle that covers some of its samples, so it keeps the
/// single-sample value except on the mesh's own triangle edges, where it mixes two
/// extrapolations of the same texture and reflection: outside the range of its 3×3
/// neighbourhood by less than 10⁻³ (the reflection looked up at an extrapolated position
/// and normal can leave it by a little).
/// (`frame_multisampling_keeps_interiors_exactly` shows exactness on flat quads.)
#[test]
fn multisampling_changes_silhouettes_of_played_frames() {
    let test = "multisampling_changes_silhouettes_of_played_frames";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let gpu = Arc::new(gpu);
    let open = |msaa| {
        Player::open(gpu.clone(), &tiny(), PlayerOptions { workers: 1, msaa, ..Default::default() })
            .unwrap()
    };
    let (mut one, mut four) = (open(1), open(4));
    assert_eq!((one.multisample().requested, one.multisample().samples), (1, 1));
    let ms = four.multisample().clone();
    if ms.samples != 4 {
        assert!(!in_ci(), "{test}: {ms:?}");
        eprintln!("{test}: skipped: {}", ms.note.unwrap_or_default());
        return;
    }
    // Larger than the traced size: more interior pixels and a longer silhouette.
    let size = (96, 72);
    let req = at(&one, &[1, 1]);
    let (a, ids_a, _) = one.render_ids(&req, size).unwrap();
    let (b, ids_b, _) = four.render_ids(&req, size).unwrap();
    assert_eq!(ids_a, ids_b, "object indices are those at pixel centres either way");
    let (w, h) = (size.0 as usize, size.1 as usize);
    let (mut area, mut partial, mut exact, mut interior) = (0usize, 0usize, 0usize, 0usize);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let p = y * w + x;
            let hood = || (0..9).map(|k| (y + k / 3 - 1) * w + x + k % 3 - 1);
            let uniform = hood().all(|q| ids_a[q] == ids_a[p]);
            let alpha = b.rgba[p * 4 + 3];
            area += (ids_a[p] != u32::MAX) as usize;
            if alpha > 0.0 && alpha < 1.0 {
                partial += 1;
                assert!(
                    !uniform,
                    "pixel ({x}, {y}) is partly covered ({alpha}) away from the silhouette"
                );
                let differ = (0..3)
                    .map(|c| (a.rgba[p * 4 + c] - b.rgba[p * 4 + c]).abs())
                    .fold(0.0, f32::max);
                assert!(
                    differ > 1e-4,
                    "partly covered pixel ({x}, {y}) keeps its single-sample colour"
                );
            }
            if uniform && ids_a[p] != u32::MAX {
                interior += 1;
                assert_eq!(alpha, 1.0, "pixel ({x}, {y}) inside the ball is wholly covered");
                let same = (0..3).all(|c| {
                    (a.rgba[p * 4 + c] - b.rgba[p * 4 + c]).abs()
                        <= 1e-6 * a.rgba[p * 4 + c].abs().max(1e-3)
                });
                exact += same as usize;
                for c in 0..3 {
                    let (lo, hi) = hood()
                        .map(|q| a.rgba[q * 4 + c])
                        .fold((f32::MAX, f32::MIN), |(l, u), v| (l.min(v), u.max(v)));
                    let v = b.rgba[p * 4 + c];
                    assert!(v >= lo - 1e-3 && v <= hi + 1e-3, "pixel ({x}, {y}) channel {c}: {v} outside its neighbourhood's [{lo}, {hi}]");
                }
            }
        }
    }
    eprintln!("{test}: {area} pixels covered, {interior} inside ({exact} unchanged), {partial} partly covered");
    assert!(interior > 200, "{interior} interior pixels");
    // A closed silhouette around `area` pixels is at least 2·sqrt(π·area) long.
    assert!(
        partial as f64 >= (area as f64).sqrt(),
        "{partial} partly covered pixels for {area} covered"
    );
    assert!(exact * 2 > interior, "{exact} of {interior} interior pixels unchanged");
}

/// PSNR of linear values, peak 1.
fn srgb(v: f32) -> f32 {
    let l = v.clamp(0.0, 1.0);
    if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// A window's surface is an sRGB texture: the frame drawn into one is the offscreen frame,
/// sRGB-encoded by the target format, with one sample per pixel and with four (resolved
/// into the sRGB target: where a pixel's samples differ, on silhouettes and on the mesh's
/// triangle edges, each sample is rounded to 8 bits before the resolve averages them and
/// the average is rounded again, one more level). Each sample is clamped to 1 first: the
/// ball without its shell stays below 1 and is drawn so everywhere; with its reflection
/// (radiance above 1 in places) a multisampled pixel near such radiance can only be darker
/// than the offscreen frame's.
#[test]
fn render_to_view_draws_the_offscreen_frame_into_an_srgb_target() {
    let Some(gpu) = gpu_or_skip("render_to_view_draws_the_offscreen_frame_into_an_srgb_target")
    else {
        return;
    };
    let gpu = Arc::new(gpu);
    let mut c = pis_format::PisReader::open(&tiny()).unwrap().load_all().unwrap();
    c.objects.iter_mut().for_each(|o| o.layers.retain(|l| !l.kind.is_shell()));
    let dir = tempfile::tempdir().unwrap();
    let diffuse = dir.path().join("tiny-without-shell.pis");
    pis_format::write(&diffuse, &c).unwrap();
    for msaa in [1, 4] {
        let clamped = view_frame_is_the_offscreen_frame(&gpu, &diffuse, msaa);
        assert_eq!(clamped, 0, "{msaa} samples: the ball without its shell is below 1");
        view_frame_is_the_offscreen_frame(&gpu, &tiny(), msaa);
    }
}

/// Checks the frame of `file` drawn into an sRGB view against its offscreen frame; returns
/// how many pixel channels lie near radiance above 1 (checked one-sided).
fn view_frame_is_the_offscreen_frame(
    gpu: &Arc<pis_play::Gpu>,
    file: &std::path::Path,
    msaa: u32,
) -> usize {
    let mut player =
        Player::open(gpu.clone(), file, PlayerOptions { workers: 1, msaa, ..Default::default() })
            .unwrap();
    let size = (48, 36);
    let req = at(&player, &[1, 1]);
    let (img, _) = player.render_image(&req, size).unwrap();
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let target = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let samples = player.multisample_for(format).samples;
    assert_eq!(
        samples,
        player.multisample().samples,
        "the sRGB view format is multisampled as the offscreen format is"
    );
    let stats = player
        .render_to_view(&req, &target.create_view(&Default::default()), format, size)
        .unwrap();
    assert_eq!(stats.codestreams_read, 0, "the textures are still on the GPU");
    let row = (size.0 * 4).div_ceil(256) * 256;
    let buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (row * size.1) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: &target,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(size.1),
            },
        },
        wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([enc.finish()]);
    let bytes = pis_play::frame::map_read(gpu, &buf).unwrap();
    let (w, h) = (size.0 as usize, size.1 as usize);
    // Whether the ball's radiance in channel c exceeds 1 around (x, y): some pixel of the
    // 3×3 neighbourhood whose colour over its coverage does (a covered sample's radiance,
    // where they agree).
    let radiance = |q: usize, c: usize| {
        if img.rgba[q * 4 + 3] > 0.0 {
            img.rgba[q * 4 + c] / img.rgba[q * 4 + 3]
        } else {
            0.0
        }
    };
    let bright = |x: usize, y: usize, c: usize| {
        (y.saturating_sub(1)..(y + 2).min(h))
            .any(|j| (x.saturating_sub(1)..(x + 2).min(w)).any(|i| radiance(j * w + i, c) > 1.0))
    };
    let (mut drawn, mut exact, mut clamped) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            let alpha = img.rgba[p * 4 + 3];
            drawn += (alpha > 0.0) as usize;
            // One level of quantization, and the driver's encoding to sRGB: llvmpipe's
            // (Mesa 22.3.6 on a Xeon) put one channel in 1908 at 1.014 levels from the exact
            // value.
            let levels = if samples > 1 { 2.0 } else { 1.1 };
            for c in 0..3 {
                let want = srgb(img.rgba[p * 4 + c]) * 255.0;
                let got = bytes[y * row as usize + x * 4 + c] as f32;
                let clamps = samples > 1 && bright(x, y, c);
                clamped += clamps as usize;
                exact += (!clamps && alpha > 0.0) as usize;
                let fits = if clamps { got <= want + levels } else { (got - want).abs() <= levels };
                assert!(fits, "{samples} samples: pixel ({x}, {y}) channel {c}: {got} vs {want}");
            }
        }
    }
    eprintln!("{}, {samples} samples: {drawn} pixels drawn; channels: {exact} drawn as the offscreen frame, {clamped} near radiance above 1", file.display());
    assert!(
        drawn > 20 && exact > 100,
        "{drawn} pixels drawn, {exact} channels as the offscreen frame"
    );
    clamped
}

/// The display filter comes from the file: samples/tiny.pis records none and keeps the box
/// resolve (each pixel's alpha the covered fraction of its own 4 samples, a multiple of ¼,
/// and its frames as with `display_filter: None`, bit for bit); the same file with the
/// provenance settings pis-pack writes resolves with the Gaussian (coverage reaching
/// neighbouring pixels: alphas off the quarters, the silhouette band wider), keeps the box
/// frame's values (to float rounding) where the 7×7 pixel centres around a pixel are one
/// object, and draws
/// single-sample frames bit for bit as without the settings. A filter given in the options
/// applies only to a file that records none.
#[test]
fn the_files_display_filter_selects_the_resolve() {
    let test = "the_files_display_filter_selects_the_resolve";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let gpu = Arc::new(gpu);
    let mut c = pis_format::PisReader::open(&tiny()).unwrap().load_all().unwrap();
    let gaussian = pis_format::DisplayFilter { sigma_px: 0.5, radius_px: 1.5 };
    c.provenance.as_mut().unwrap().settings.extend(gaussian.settings());
    let dir = tempfile::tempdir().unwrap();
    let with = dir.path().join("tiny-display-filter.pis");
    pis_format::write(&with, &c).unwrap();
    let open = |path: &PathBuf, msaa, display_filter| {
        Player::open(
            gpu.clone(),
            path,
            PlayerOptions { workers: 1, msaa, display_filter, ..Default::default() },
        )
        .unwrap()
    };
    let mut plain = open(&tiny(), 4, None);
    if plain.multisample().samples != 4 {
        assert!(!in_ci(), "{test}: {:?}", plain.multisample());
        eprintln!("{test}: skipped: {}", plain.multisample().note.clone().unwrap_or_default());
        return;
    }
    let mut filtered = open(&with, 4, None);
    assert_eq!(plain.display_filter(), None);
    assert_eq!(filtered.display_filter(), Some((gaussian, true)));
    // An option's filter is used only where the file records none.
    let wide = pis_format::DisplayFilter { sigma_px: 1.0, radius_px: 1.5 };
    assert_eq!(open(&tiny(), 4, Some(wide)).display_filter(), Some((wide, false)));
    assert_eq!(open(&with, 4, Some(wide)).display_filter(), Some((gaussian, true)));
    let size = (96, 72);
    let req = at(&plain, &[1, 1]);
    let (a, ids, _) = plain.render_ids(&req, size).unwrap();
    let (b, ids_b, _) = filtered.render_ids(&req, size).unwrap();
    assert_eq!(ids, ids_b);
    // The box resolve, as before the display filter existed: a fresh player, default options.
    let (again, _) =
        Player::open(gpu.clone(), &tiny(), PlayerOptions { workers: 1, ..Default::default() })
            .unwrap()
            .render_image(&req, size)
            .unwrap();
    assert!(
        a.rgba.iter().zip(&again.rgba).all(|(x, y)| x.to_bits() == y.to_bits()),
        "frames without a display filter differ"
    );
    let quarter = |v: f32| ((v * 4.0).round() - v * 4.0).abs() < 1e-6;
    let (w, h) = (size.0 as usize, size.1 as usize);
    let (mut box_partial, mut gauss_partial, mut off_quarter, mut interior) =
        (0usize, 0usize, 0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            let (aa, ab) = (a.rgba[p * 4 + 3], b.rgba[p * 4 + 3]);
            assert!(quarter(aa), "box resolve: pixel ({x}, {y}) alpha {aa}");
            box_partial += (aa > 0.0 && aa < 1.0) as usize;
            gauss_partial += (ab > 0.0 && ab < 1.0) as usize;
            off_quarter += !quarter(ab) as usize;
            let inside = x >= 3
                && y >= 3
                && x + 3 < w
                && y + 3 < h
                && (0..49).all(|k| ids[(y + k / 7 - 3) * w + x + k % 7 - 3] == ids[p]);
            if inside && ids[p] != u32::MAX {
                interior += 1;
                // Where two triangles of the ball's mesh shade a pixel's samples, the box
                // and the resolve's running mean average the same 4 values in another order.
                for ch in 0..4 {
                    let (va, vb) = (a.rgba[p * 4 + ch], b.rgba[p * 4 + ch]);
                    assert!(
                        (va - vb).abs() <= 1e-6 * va.abs() + 1e-7,
                        "pixel ({x}, {y}) inside the ball: box {va}, Gaussian {vb}"
                    );
                }
            }
        }
    }
    eprintln!("{test}: partly covered pixels: box {box_partial}, Gaussian {gauss_partial} ({off_quarter} off the quarters); {interior} interior pixels unchanged");
    assert!(interior > 200, "{interior} interior pixels");
    // The Gaussian reaches 1.5 px: about three pixels across the silhouette against the box's one.
    assert!(
        gauss_partial > box_partial * 2,
        "partly covered: box {box_partial}, Gaussian {gauss_partial}"
    );
    assert!(off_quarter * 2 > gauss_partial, "{off_quarter} of {gauss_partial} off the quarters");
    // Single-sample frames ignore the display filter.
    let (one_plain, _) = open(&tiny(), 1, None).render_image(&req, size).unwrap();
    let (one_with, _) = open(&with, 1, None).render_image(&req, size).unwrap();
    assert!(
        one_plain.rgba.iter().zip(&one_with.rgba).all(|(x, y)| x.to_bits() == y.to_bits()),
        "single-sample frames differ"
    );
}

/// tiny.pis with `texcoords` as every object's mesh texture coordinates and `cut` as every
/// surface block's branch cuts, written into `dir` as `name`.
fn tiny_with(
    dir: &std::path::Path,
    name: &str,
    uv: impl Fn([f32; 2], [f32; 6]) -> [f32; 2],
    cut: [Option<f32>; 2],
) -> PathBuf {
    let mut c = pis_format::PisReader::open(&tiny()).unwrap().load_all().unwrap();
    for o in &mut c.objects {
        let affine = o.layers.iter().flat_map(|l| &l.blocks).find_map(|b| match b.placement {
            pis_format::Placement::Surface { affine, .. } => Some(affine),
            _ => None,
        });
        let (Some(affine), Some(t)) = (affine, o.mesh.texcoords.as_mut()) else { continue };
        t.iter_mut().for_each(|w| *w = uv(*w, affine));
        for b in o.layers.iter_mut().flat_map(|l| &mut l.blocks) {
            if let pis_format::Placement::Surface { cut: c, .. } = &mut b.placement {
                *c = cut;
            }
        }
    }
    let path = dir.join(name);
    pis_format::write(&path, &c).unwrap();
    path
}

/// Branch cuts (SPEC.md 7.3) in played frames: a file whose mesh coordinates are tiny.pis's
/// shifted by (0.3, 0.55) (u over [0.3, 1.3], a wrapped range) with cuts at u = 0.3 and
/// v = 0.55 plays as the same file with the cuts applied to its coordinates beforehand and
/// no cut (≥ 50 dB), and unlike the shifted file played without its cuts.
#[test]
fn branch_cuts_play_as_cut_mesh_coordinates() {
    let test = "branch_cuts_play_as_cut_mesh_coordinates";
    let Some(gpu) = gpu_or_skip(test) else { return };
    let gpu = Arc::new(gpu);
    let cut = [Some(0.3f32), Some(0.55f32)];
    let shift = |[u, v]: [f32; 2], _| [u + 0.3, v + 0.55];
    let dir = tempfile::tempdir().unwrap();
    let with_cut = tiny_with(dir.path(), "cut.pis", shift, cut);
    let pre_cut = tiny_with(
        dir.path(),
        "pre-cut.pis",
        |w, affine| pis_compile::TextureTransform { values: affine, cut }.cut_uv(shift(w, affine)),
        [None; 2],
    );
    let uncut = tiny_with(dir.path(), "uncut.pis", shift, [None; 2]);
    let open = |p: &PathBuf| {
        Player::open(gpu.clone(), p, PlayerOptions { workers: 1, ..Default::default() }).unwrap()
    };
    let (mut a, mut b, mut u) = (open(&with_cut), open(&pre_cut), open(&uncut));
    let size = a.image_size();
    for samples in [[0, 0], [1, 1]] {
        let req = at(&a, &samples);
        let (x, _) = a.render_image(&req, size).unwrap();
        let (y, _) = b.render_image(&req, size).unwrap();
        let (z, _) = u.render_image(&req, size).unwrap();
        let (same, differ) = (psnr(&x.rgba, &y.rgba), psnr(&z.rgba, &y.rgba));
        eprintln!("{test} {samples:?}: {same:.2} dB against the coordinates cut beforehand, {differ:.2} dB against the file without its cuts");
        assert!(same >= 50.0, "point {samples:?}: cut {same:.2} dB against pre-cut coordinates");
        assert!(
            differ < 30.0,
            "point {samples:?}: the cuts change the frame ({differ:.2} dB without them)"
        );
    }
}

/// Half floats (SPEC.md 6.6, `--texture-precision`): tiny.pis's diffuse texture and shell
/// held in `Rgba16Float` draw every sample within half floats' rounding of the frames drawn
/// from `Rgba32Float` textures, rebuilt on the GPU and on the workers, and the workers
/// upload half the bytes. A texel below 1 rounds to half floats within 2^-12, and a pixel
/// is a weighted mean of texels, so its error is at most 2^-12: 72.2 dB (uniform rounding
/// errors average 77 dB); frames that are equal would mean no half float was drawn.
#[test]
fn half_float_textures_draw_within_their_rounding_of_full_ones() {
    use pis_play::TexturePrecision;
    let test = "half_float_textures_draw_within_their_rounding_of_full_ones";
    let Some(gpu) = gpu_or_skip(test) else {
        return;
    };
    let gpu = Arc::new(gpu);
    for rebuild in [Rebuild::Gpu, Rebuild::Workers] {
        let open = |precision| {
            let options =
                PlayerOptions { workers: 2, msaa: 1, rebuild, precision, ..Default::default() };
            Player::open(gpu.clone(), &tiny(), options).unwrap()
        };
        let (mut full, mut half) = (open(TexturePrecision::Full), open(TexturePrecision::Half));
        assert!(half.texture_precision().half() && !full.texture_precision().half());
        let size = full.image_size();
        for samples in [[0, 0], [1, 0], [1, 1]] {
            let (a, sa) = full.render_image(&at(&full, &samples), size).unwrap();
            let (b, sb) = half.render_image(&at(&half, &samples), size).unwrap();
            let db = psnr(&a.rgba, &b.rgba);
            eprintln!(
                "{rebuild:?} {samples:?}: half against full {db:.1} dB, uploads {} / {} bytes",
                sb.upload_bytes, sa.upload_bytes
            );
            let bound = 20.0 * 4096f64.log10();
            assert!(db >= bound && db.is_finite(), "{rebuild:?} at {samples:?}: {db:.1} dB");
            if rebuild == Rebuild::Workers {
                assert_eq!(sb.upload_bytes * 2, sa.upload_bytes, "{rebuild:?} at {samples:?}");
            }
        }
    }
}
