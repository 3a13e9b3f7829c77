//! An object's own texture filter (SPEC.md 6.6, since 1.4): a `filter.NAME` provenance
//! setting names the filter the object's textures were solved for where it is not the
//! file's. Such a file is valid and written as minor version 4; a setting naming no object or
//! no filter breaks rule 9001.

use pis_format::samples::tiny;
use pis_format::*;

/// `tiny` with provenance settings `settings`.
fn with_settings(settings: &[(&str, &str)]) -> Container {
    let mut c = tiny().unwrap();
    c.provenance = Some(Provenance {
        tool: "t".into(),
        source: "s".into(),
        raw_image_bytes: 0,
        settings: settings.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
    });
    c
}

fn rules(c: &Container) -> Vec<u16> {
    validate_bytes(to_bytes_unchecked(c)).issues.iter().map(|i| i.id).collect()
}

#[test]
fn an_object_with_a_filter_of_its_own_is_valid_and_written_as_minor_version_4() {
    let name = tiny().unwrap().objects[0].name.clone();
    let (k, v) = FileFilter::Bilinear.object_setting(&name);
    let c = with_settings(&[("filter", "trilinear"), (&k, &v)]);
    assert_eq!(rules(&c), Vec::<u16>::new());
    let bytes = to_bytes(&c).unwrap();
    assert_eq!(u16::from_le_bytes([bytes[10], bytes[11]]), 4, "minor version");
    let r = PisReader::from_bytes(bytes).unwrap();
    let names: Vec<&str> = r.container().objects.iter().map(|o| o.name.as_str()).collect();
    let filters = FileFilter::per_object(r.container().provenance.as_ref(), &names).unwrap();
    assert_eq!(filters[0], FileFilter::Bilinear);
    let plain = to_bytes(&with_settings(&[("filter", "trilinear")])).unwrap();
    assert_eq!(u16::from_le_bytes([plain[10], plain[11]]), 2, "a file without one");
}

#[test]
fn a_filter_setting_naming_no_object_or_no_filter_breaks_rule_9001() {
    let name = tiny().unwrap().objects[0].name.clone();
    for bad in
        [("filter.NoSuchObject".to_string(), "bilinear"), (format!("filter.{name}"), "cubic")]
    {
        let c = with_settings(&[(&bad.0, bad.1)]);
        assert_eq!(rules(&c), vec![9001], "{bad:?}");
    }
}
