fn main() {
    let a: Vec<String> = std::env::args().collect();
    let cover = if a.get(3).map(String::as_str) == Some("sphere") {
        pis_compile::relight::Cover::Sphere
    } else {
        pis_compile::relight::Cover::Hemisphere(glam::Vec3::Y)
    };
    let rows =
        pis_eval::relight::ceiling(a[1].as_ref(), a[2].as_ref(), &[1, 2, 3, 4, 5, 6, 7], cover)
            .unwrap();
    for r in rows {
        println!(
            "{:?} {} held {:.2} samples {:.2}",
            r.band, r.coefficients, r.held_out_db, r.samples_db
        );
    }
}
