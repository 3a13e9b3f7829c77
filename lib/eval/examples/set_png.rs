fn main() {
    let a: Vec<String> = std::env::args().collect();
    let set = pis_trace::set::RaySet::open(&a[1]).unwrap();
    for i in a[3..].iter().map(|s| s.parse::<usize>().unwrap()) {
        let p = set.read_point(i).unwrap();
        let c = p.layer("combined").unwrap();
        let (w, h) = (c.width, c.height);
        let mut img = image::RgbImage::new(w, h);
        for (k, px) in img.pixels_mut().enumerate() {
            for ch in 0..3 {
                px.0[ch] = (pis_eval::metrics::srgb_encode(c.planes[ch][k]) * 255.0).round() as u8;
            }
        }
        img.save(format!("{}/p{i}.png", a[2])).unwrap();
    }
}
