//! What `--representation auto` reports of each object, held to its screen's rule.

/// Every object of the report `r` of a default pack (`--representation auto`) with an
/// alternative representation was screened as docs/TOOLS.md says: solved again where its
/// textures solved 6 dB or more below the other objects, weighed where the alternative
/// solved within 1 dB of them, stored as the alternative only where weighed; demo1's vase,
/// table top and glass cup have one, its walls, floor and stand none.
pub fn assert_demo1_followed_its_screen(r: &serde_json::Value) {
    let mut screened = 0;
    for o in r["objects"].as_array().expect("objects") {
        let name = o["name"].as_str().unwrap();
        let Some(a) = o.get("auto") else {
            assert!(["Walls", "Floor", "TableStand"].contains(&name), "{name}: no auto: {o}");
            continue;
        };
        screened += 1;
        let textures = a["textures_solved_db"].as_f64().unwrap();
        let solved_again = a["others_solved_db"].as_f64().is_none_or(|d| d - textures >= 6.0);
        assert_eq!(a["alternative_solved_db"].is_number(), solved_again, "{name}: {a}");
        let weighed = a["alternative_solved_db"].as_f64().is_some_and(|alt| alt >= textures - 1.0);
        assert_eq!(a["weighed"].as_bool(), Some(weighed), "{name}: {a}");
        let kept = a["kept"].as_bool().unwrap();
        assert!(!kept || weighed, "{name}: kept unweighed: {a}");
        assert_eq!(kept, o["representation"] == a["alternative"], "{name}: {o}");
    }
    assert_eq!(screened, 3, "{r}");
}
