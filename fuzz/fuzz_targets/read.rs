//! Any byte string: validation and the reader return errors, never panic; when a file opens,
//! every texture at every point is decoded, and the lossless master read and decoded.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pis_format::{validate_bytes, PisReader};

fuzz_target!(|data: &[u8]| {
    let _ = validate_bytes(data.to_vec());
    if let Ok(r) = PisReader::from_bytes(data.to_vec()) {
        let c = r.container();
        for p in 0..c.space.point_count().min(64) {
            let point = c.space.point(p);
            for (oi, o) in c.objects.iter().enumerate() {
                for li in 0..o.layers.len() {
                    let _ = r.texture(oi, li, &point);
                }
            }
        }
        if let Ok(masters) = r.masters() {
            for m in &masters {
                for (li, l) in m.layers.iter().enumerate() {
                    for s in 0..l.samples.len().min(64) {
                        let _ = m.texture(c, li, s);
                    }
                }
            }
        }
    }
});
