//! Any codestream, for small plane shapes taken from the first bytes: every codec's decoder
//! returns an image of the declared size or an error, never panics; a wavelet image is also
//! decoded from every prefix.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pis_codec::{decode, value_count, CodecId, PlaneShape};

fuzz_target!(|data: &[u8]| {
    if data.len() < 4 {
        return;
    }
    let codec = CodecId::ALL[(data[0] % 4) as usize];
    let planes = [
        PlaneShape::new(1 + (data[1] % 64) as u32, 1 + (data[2] % 64) as u32, 1 + (data[3] % 4) as u32),
        PlaneShape::new(1 + (data[1] % 7) as u32, 1 + (data[2] % 5) as u32, 1 + (data[3] % 4) as u32),
    ];
    let n = value_count(&planes).unwrap();
    let body = &data[4..];
    if let Ok(v) = decode(codec, &planes, body) {
        assert_eq!(v.len(), n);
    }
    if codec == CodecId::Wavelet {
        for cut in (0..body.len()).step_by(7) {
            if let Ok(v) = decode(codec, &planes, &body[..cut]) {
                assert_eq!(v.len(), n);
            }
        }
    }
});
