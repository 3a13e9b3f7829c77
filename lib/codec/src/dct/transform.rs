//! The orthonormal 8×8 DCT-II and its inverse (SPEC.md 11.5).

use std::sync::OnceLock;

/// `cos[u][x] = c(u) · cos((2x + 1)uπ / 16)` with c(0) = √(1/8), c(u) = √(2/8).
fn table() -> &'static [[f32; 8]; 8] {
    static T: OnceLock<[[f32; 8]; 8]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [[0.0f32; 8]; 8];
        for (u, row) in t.iter_mut().enumerate() {
            let c = if u == 0 { (1.0f64 / 8.0).sqrt() } else { (2.0f64 / 8.0).sqrt() };
            for (x, v) in row.iter_mut().enumerate() {
                *v = (c * (((2 * x + 1) * u) as f64 * std::f64::consts::PI / 16.0).cos()) as f32;
            }
        }
        t
    })
}

/// Forward DCT of a row-major 8×8 block, in place.
pub fn forward(b: &mut [f32; 64]) {
    let t = table();
    let mut tmp = [0.0f32; 64];
    for y in 0..8 {
        for u in 0..8 {
            tmp[y * 8 + u] = (0..8).map(|x| t[u][x] * b[y * 8 + x]).sum();
        }
    }
    for v in 0..8 {
        for u in 0..8 {
            b[v * 8 + u] = (0..8).map(|y| t[v][y] * tmp[y * 8 + u]).sum();
        }
    }
}

/// Inverse DCT of a row-major 8×8 block of coefficients, in place.
pub fn inverse(b: &mut [f32; 64]) {
    let t = table();
    let mut tmp = [0.0f32; 64];
    for v in 0..8 {
        for x in 0..8 {
            tmp[v * 8 + x] = (0..8).map(|u| t[u][x] * b[v * 8 + u]).sum();
        }
    }
    for y in 0..8 {
        for x in 0..8 {
            b[y * 8 + x] = (0..8).map(|v| t[v][y] * tmp[v * 8 + x]).sum();
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn round_trip() {
        let mut b = [0.0f32; 64];
        for (i, v) in b.iter_mut().enumerate() {
            *v = ((i * 37) % 11) as f32 - 5.0;
        }
        let orig = b;
        super::forward(&mut b);
        assert!((b[0] - orig.iter().sum::<f32>() / 8.0).abs() < 1e-4);
        super::inverse(&mut b);
        for (a, c) in orig.iter().zip(&b) {
            assert!((a - c).abs() < 1e-4);
        }
    }
}
