//! Multi-layer OpenEXR encoding of one point's images: a single part whose f32 channels are
//! named `<layer>.<channel>` (`combined.R`, `object.vase.diffuse.G`).

use crate::error::TraceError;
use crate::layers::{LayerImage, PointImages};
use exr::prelude::*;
use std::io::Cursor;
use std::path::Path;

/// Encodes `images` as an OpenEXR file (ZIP compression, increasing scan lines).
pub fn encode_exr(images: &PointImages, path: &Path) -> std::result::Result<Vec<u8>, TraceError> {
    let size = (images.width as usize, images.height as usize);
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    for layer in &images.layers {
        for (c, plane) in layer.channels.iter().zip(&layer.planes) {
            channels.push(AnyChannel::new(
                format!("{}.{}", layer.name, c).as_str(),
                FlatSamples::F32(plane.clone()),
            ));
        }
    }
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    let mut out = Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut out)
        .map_err(|e| TraceError::Exr { path: path.to_path_buf(), message: e.to_string() })?;
    Ok(out.into_inner())
}

/// Decodes an OpenEXR file into layers, grouping channels `<layer>.<channel>` by layer
/// (the channel is the part after the last dot). Channels are converted to f32.
pub fn decode_exr(bytes: &[u8], path: &Path) -> std::result::Result<PointImages, TraceError> {
    let err =
        |e: exr::error::Error| TraceError::Exr { path: path.to_path_buf(), message: e.to_string() };
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(err)?;
    let size = image.layer_data.size;
    let (width, height) = (size.0 as u32, size.1 as u32);
    let mut layers: Vec<LayerImage> = Vec::new();
    for ch in &image.layer_data.channel_data.list {
        let full = ch.name.to_string();
        let (layer, c) = match full.rsplit_once('.') {
            Some((l, c)) => (l.to_string(), c.to_string()),
            None => (String::new(), full.clone()),
        };
        let plane: Vec<f32> = ch.sample_data.values_as_f32().collect();
        if plane.len() != size.0 * size.1 {
            return Err(TraceError::Exr {
                path: path.to_path_buf(),
                message: format!(
                    "channel {full} has {} samples for a {}x{} image (subsampled channels are not supported)",
                    plane.len(),
                    size.0,
                    size.1
                ),
            });
        }
        match layers.iter_mut().find(|l| l.name == layer) {
            Some(l) => {
                l.channels.push(c);
                l.planes.push(plane);
            }
            None => layers.push(LayerImage {
                name: layer,
                channels: vec![c],
                width,
                height,
                planes: vec![plane],
            }),
        }
    }
    // Channel order within a layer: R, G, B, A, then the rest alphabetically.
    for l in &mut layers {
        let rank = |c: &str| match c {
            "R" => 0,
            "G" => 1,
            "B" => 2,
            "A" => 3,
            _ => 4,
        };
        let mut idx: Vec<usize> = (0..l.channels.len()).collect();
        idx.sort_by(|&a, &b| {
            rank(&l.channels[a]).cmp(&rank(&l.channels[b])).then(l.channels[a].cmp(&l.channels[b]))
        });
        l.channels = idx.iter().map(|&i| l.channels[i].clone()).collect();
        let mut planes = std::mem::take(&mut l.planes);
        l.planes = idx.iter().map(|&i| std::mem::take(&mut planes[i])).collect();
    }
    Ok(PointImages { width, height, layers })
}
