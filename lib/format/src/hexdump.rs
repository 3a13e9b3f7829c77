//! Annotated hex dumps: each labelled field on its own line(s), 16 bytes a line at most.

use std::fmt::Write;

use crate::Span;

/// Renders `bytes` with the labels in `spans` (which must cover the bytes in order).
pub fn annotate(bytes: &[u8], spans: &[Span]) -> String {
    let mut out = String::new();
    for s in spans {
        let data = &bytes[s.start..s.start + s.len];
        for (i, line) in data.chunks(16).enumerate() {
            let hex: Vec<String> = line.iter().map(|b| format!("{b:02x}")).collect();
            let label = if i == 0 { s.label.as_str() } else { "" };
            let mut label = label.to_string();
            if label.len() > 90 {
                label.truncate(87);
                label.push_str("...");
            }
            let _ = writeln!(out, "{:08x}  {:<47}  {}", s.start + 16 * i, hex.join(" "), label);
        }
    }
    out
}

/// Parses the hex columns of [`annotate`]'s output back into bytes (to check a dump).
pub fn parse(dump: &str) -> Vec<u8> {
    let mut out = Vec::new();
    for line in dump.lines() {
        let Some(rest) = line.get(10..57) else {
            continue;
        };
        if !line.get(..8).is_some_and(|o| o.chars().all(|c| c.is_ascii_hexdigit())) {
            continue;
        }
        out.extend(rest.split_whitespace().filter_map(|h| u8::from_str_radix(h, 16).ok()));
    }
    out
}
