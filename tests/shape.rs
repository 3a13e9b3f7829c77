//! The code's shape, checked on every run: no import circle among a crate's files (no two
//! files, and no loop of files, that import each other), no function in lib/ over
//! [`MAX_FN_LINES`] lines, and no source file over [`MAX_FILE_LINES`] lines.
//!
//! The checks read the sources with a small lexer (comments, strings and character literals
//! blanked, lines kept), follow each crate's `mod` declarations from its roots to map module
//! paths to files, and resolve every `crate::`, `super::` and `self::` path (in `use` trees
//! and in code) to the deepest module file it names. An import circle is a strongly connected
//! set of two or more files in that graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The longest function in lib/, in lines from its `fn` to its closing brace.
const MAX_FN_LINES: usize = 150;
/// The longest source file in the workspace, in lines.
const MAX_FILE_LINES: usize = 800;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The workspace's crates: every folder with a Cargo.toml under lib/, bins/ and samples/.
fn crate_dirs() -> Vec<PathBuf> {
    let mut dirs = vec![repo().join("bins"), repo().join("samples/generator")];
    let mut libs: Vec<PathBuf> = std::fs::read_dir(repo().join("lib"))
        .expect("lib/")
        .map(|e| e.expect("lib/ entry").path())
        .filter(|p| p.join("Cargo.toml").is_file())
        .collect();
    libs.sort();
    dirs.extend(libs);
    dirs
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut paths: Vec<PathBuf> = entries.map(|e| e.expect("entry").path()).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "target") {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// A source with comments, string and character literals replaced by spaces; newlines kept.
fn blank(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    let keep = |out: &mut String, ch: char| out.push(if ch == '\n' { '\n' } else { ' ' });
    while i < c.len() {
        let at = |k: usize| c.get(i + k).copied().unwrap_or('\0');
        if at(0) == '/' && at(1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
                out.push(' ');
            }
        } else if at(0) == '/' && at(1) == '*' {
            let mut depth = 0;
            loop {
                let (a, b) =
                    (c.get(i).copied().unwrap_or('\0'), c.get(i + 1).copied().unwrap_or('\0'));
                if i >= c.len() {
                    break;
                }
                if a == '/' && b == '*' {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if a == '*' && b == '/' {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    keep(&mut out, a);
                    i += 1;
                }
            }
        } else if let Some(len) = raw_string_start(&c, i) {
            // r"..." or r#"..."# (also br): skip to the quote and the same number of hashes.
            let hashes = len - 2 - usize::from(c[i] == 'b');
            for _ in 0..len {
                out.push(' ');
            }
            i += len;
            while i < c.len() {
                if c[i] == '"' && (1..=hashes).all(|k| c.get(i + k) == Some(&'#')) {
                    for _ in 0..=hashes {
                        out.push(' ');
                    }
                    i += 1 + hashes;
                    break;
                }
                keep(&mut out, c[i]);
                i += 1;
            }
        } else if at(0) == '"' {
            out.push(' ');
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < c.len() {
                    keep(&mut out, c[i]);
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if at(0) == '\'' && (at(1) == '\\' || (at(2) == '\'' && at(1) != '\'')) {
            // A character literal ('x', '\n', '\u{..}'); a lifetime ('a) has no closing quote.
            out.push(' ');
            i += 1;
            if c[i] == '\\' {
                out.push(' ');
                i += 1;
            }
            while i < c.len() && c[i] != '\'' {
                out.push(' ');
                i += 1;
            }
            out.push(' ');
            i += 1;
        } else {
            out.push(at(0));
            i += 1;
        }
    }
    out
}

/// The length of a raw string's opening (`r"`, `r#"`, `br##"`) at `i`, if one starts there.
fn raw_string_start(c: &[char], i: usize) -> Option<usize> {
    if i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_') {
        return None;
    }
    let mut j = i;
    if c.get(j) == Some(&'b') {
        j += 1;
    }
    if c.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    while c.get(j) == Some(&'#') {
        j += 1;
    }
    (c.get(j) == Some(&'"')).then_some(j + 1 - i)
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Ident(String),
    Punct(char),
}

/// Identifiers (with `::` as the punctuation `:` twice) and punctuation, each with its line.
fn tokens(blanked: &str) -> Vec<(Token, usize)> {
    let mut out = Vec::new();
    let mut line = 1;
    let mut word = String::new();
    let mut word_line = 1;
    for ch in blanked.chars() {
        if ch.is_alphanumeric() || ch == '_' {
            if word.is_empty() {
                word_line = line;
            }
            word.push(ch);
            continue;
        }
        if !word.is_empty() {
            out.push((Token::Ident(std::mem::take(&mut word)), word_line));
        }
        if ch == '\n' {
            line += 1;
        } else if !ch.is_whitespace() {
            out.push((Token::Punct(ch), line));
        }
    }
    if !word.is_empty() {
        out.push((Token::Ident(word), word_line));
    }
    out
}

fn ident(t: Option<&(Token, usize)>) -> Option<&str> {
    match t {
        Some((Token::Ident(s), _)) => Some(s),
        _ => None,
    }
}

fn is_punct(t: Option<&(Token, usize)>, p: char) -> bool {
    matches!(t, Some((Token::Punct(q), _)) if *q == p)
}

/// Every function with a body: its name, first line and length in lines.
fn functions(toks: &[(Token, usize)]) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    for i in 0..toks.len() {
        if ident(toks.get(i)) != Some("fn") {
            continue;
        }
        let Some(name) = ident(toks.get(i + 1)) else { continue };
        // The body is the first `{` outside parentheses and angle-free signature parts,
        // unless a `;` ends a declaration first.
        let mut j = i + 2;
        let mut parens = 0i32;
        let body = loop {
            match toks.get(j) {
                None => break None,
                Some((Token::Punct('('), _)) | Some((Token::Punct('['), _)) => parens += 1,
                Some((Token::Punct(')'), _)) | Some((Token::Punct(']'), _)) => parens -= 1,
                Some((Token::Punct(';'), _)) if parens == 0 => break None,
                Some((Token::Punct('{'), _)) if parens == 0 => break Some(j),
                _ => {}
            }
            j += 1;
        };
        let Some(open) = body else { continue };
        let mut depth = 0;
        for (k, (t, line)) in toks.iter().enumerate().skip(open) {
            match t {
                Token::Punct('{') => depth += 1,
                Token::Punct('}') => {
                    depth -= 1;
                    if depth == 0 {
                        let first = toks[i].1;
                        out.push((name.to_string(), first, line + 1 - first));
                        let _ = k;
                        break;
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// A file's `mod name;` declarations and the module paths of its inline `mod name { }`
/// blocks, and every path it names that starts with `crate`, `super` or `self`, each
/// as (the inline module it appears in, relative to the file's module; the path's segments).
struct FileSyntax {
    mods: Vec<(Vec<String>, String)>,
    paths: Vec<(Vec<String>, Vec<String>)>,
}

fn syntax(toks: &[(Token, usize)]) -> FileSyntax {
    let mut mods = Vec::new();
    let mut paths = Vec::new();
    let mut inline: Vec<(String, i32)> = Vec::new();
    let mut depth = 0i32;
    let mut i = 0;
    while i < toks.len() {
        let here: Vec<String> = inline.iter().map(|(n, _)| n.clone()).collect();
        match &toks[i].0 {
            Token::Punct('{') => depth += 1,
            Token::Punct('}') => {
                depth -= 1;
                if inline.last().is_some_and(|(_, d)| *d == depth) {
                    inline.pop();
                }
            }
            Token::Ident(w) if w == "mod" => {
                if let Some(name) = ident(toks.get(i + 1)) {
                    if is_punct(toks.get(i + 2), ';') {
                        mods.push((here.clone(), name.to_string()));
                    } else if is_punct(toks.get(i + 2), '{') {
                        inline.push((name.to_string(), depth));
                        depth += 1;
                        i += 3;
                        continue;
                    }
                }
            }
            Token::Ident(w) if w == "use" => {
                let mut j = i + 1;
                let mut out = Vec::new();
                use_tree(toks, &mut j, Vec::new(), &mut out);
                for p in out {
                    if p.first().is_some_and(|s| s == "crate" || s == "super" || s == "self") {
                        paths.push((here.clone(), p));
                    }
                }
                i = j;
                continue;
            }
            Token::Ident(w)
                if (w == "crate" || w == "super" || w == "self") && is_path_sep(toks, i + 1) =>
            {
                let prev_sep = i >= 2 && is_path_sep(toks, i - 2);
                if !prev_sep {
                    let mut p = vec![w.clone()];
                    let mut j = i + 1;
                    while is_path_sep(toks, j) {
                        match ident(toks.get(j + 2)) {
                            Some(s) => p.push(s.to_string()),
                            None => break,
                        }
                        j += 3;
                    }
                    paths.push((here.clone(), p));
                    i = j;
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
    FileSyntax { mods, paths }
}

fn is_path_sep(toks: &[(Token, usize)], i: usize) -> bool {
    is_punct(toks.get(i), ':') && is_punct(toks.get(i + 1), ':')
}

/// Expands a use tree from `*j` into full paths; leaves `*j` after its end.
fn use_tree(
    toks: &[(Token, usize)],
    j: &mut usize,
    prefix: Vec<String>,
    out: &mut Vec<Vec<String>>,
) {
    let mut path = prefix;
    loop {
        match toks.get(*j) {
            Some((Token::Ident(s), _)) if s == "as" => {
                *j += 2;
                out.push(path);
                return;
            }
            Some((Token::Ident(s), _)) => {
                path.push(s.clone());
                *j += 1;
            }
            Some((Token::Punct(':'), _)) => *j += 1,
            Some((Token::Punct('*'), _)) => {
                *j += 1;
                out.push(path);
                return;
            }
            Some((Token::Punct('{'), _)) => {
                *j += 1;
                loop {
                    use_tree(toks, j, path.clone(), out);
                    match toks.get(*j) {
                        Some((Token::Punct(','), _)) => *j += 1,
                        _ => break,
                    }
                    if is_punct(toks.get(*j), '}') {
                        break;
                    }
                }
                *j += 1; // the closing brace
                if is_punct(toks.get(*j), ';') {
                    *j += 1;
                }
                return;
            }
            Some((Token::Punct(';'), _)) => {
                *j += 1;
                out.push(path);
                return;
            }
            _ => {
                out.push(path);
                return;
            }
        }
    }
}

/// One crate's module tree: module path → file, and each file's own module path.
struct Modules {
    files: BTreeMap<Vec<String>, PathBuf>,
}

impl Modules {
    /// Follows `mod` declarations from a root file (its module path is `[]`).
    fn from_root(root: &Path, parsed: &BTreeMap<PathBuf, FileSyntax>) -> Modules {
        let mut files = BTreeMap::new();
        let mut todo = vec![(Vec::<String>::new(), root.to_path_buf(), true)];
        while let Some((module, file, owns_dir)) = todo.pop() {
            let Some(syn) = parsed.get(&file) else { continue };
            let dir = if owns_dir {
                file.parent().expect("a file's folder").to_path_buf()
            } else {
                file.with_extension("")
            };
            for (inline, name) in &syn.mods {
                let sub = inline.iter().fold(dir.clone(), |d, m| d.join(m));
                let (flat, nested) =
                    (sub.join(format!("{name}.rs")), sub.join(name).join("mod.rs"));
                let child = if flat.is_file() { flat } else { nested };
                let mut path = module.clone();
                path.extend(inline.iter().cloned());
                path.push(name.clone());
                let owns = child.file_name().is_some_and(|n| n == "mod.rs");
                todo.push((path, child, owns));
            }
            files.insert(module, file);
        }
        Modules { files }
    }

    /// The file of the deepest module named by an absolute module path's prefix.
    fn file_of(&self, path: &[String]) -> Option<&PathBuf> {
        (0..=path.len()).rev().find_map(|n| self.files.get(&path[..n]))
    }
}

/// Each crate root's files and the import edges between them.
fn import_edges() -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for dir in crate_dirs() {
        let mut all = Vec::new();
        rust_files(&dir, &mut all);
        let parsed: BTreeMap<PathBuf, FileSyntax> = all
            .iter()
            .map(|f| {
                (f.clone(), syntax(&tokens(&blank(&std::fs::read_to_string(f).expect("source")))))
            })
            .collect();
        let mut roots = vec![dir.join("src/lib.rs"), dir.join("src/main.rs")];
        for sub in ["src/bin", "tests", "benches", "examples"] {
            let mut top: Vec<PathBuf> = std::fs::read_dir(dir.join(sub))
                .into_iter()
                .flatten()
                .map(|e| e.expect("entry").path())
                .filter(|p| p.extension().is_some_and(|e| e == "rs"))
                .collect();
            top.sort();
            roots.extend(top);
        }
        for root in roots.into_iter().filter(|r| r.is_file()) {
            let modules = Modules::from_root(&root, &parsed);
            for (module, file) in &modules.files {
                let syn = &parsed[file];
                for (inline, path) in &syn.paths {
                    let mut here = module.clone();
                    here.extend(inline.iter().cloned());
                    let Some(abs) = absolute(&here, path) else { continue };
                    if let Some(target) = modules.file_of(&abs) {
                        if target != file {
                            edges.entry(file.clone()).or_default().insert(target.clone());
                        }
                    }
                }
            }
        }
    }
    edges
}

/// A `crate`/`super`/`self` path made absolute from the module it appears in.
fn absolute(here: &[String], path: &[String]) -> Option<Vec<String>> {
    let mut base: Vec<String> = here.to_vec();
    let mut rest = path;
    match rest.first().map(String::as_str) {
        Some("crate") => {
            base.clear();
            rest = &rest[1..];
        }
        Some("self") => rest = &rest[1..],
        _ => {}
    }
    while rest.first().is_some_and(|s| s == "super") {
        base.pop()?;
        rest = &rest[1..];
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

/// The strongly connected sets of two or more files (Tarjan's algorithm).
fn circles(edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct State<'a> {
        edges: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on_stack: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<PathBuf>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a PathBuf) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut set = Vec::new();
            loop {
                let w = s.stack.pop().expect("on the stack");
                s.on_stack.remove(w);
                set.push(w.clone());
                if w == v {
                    break;
                }
            }
            if set.len() > 1 {
                set.sort();
                s.out.push(set);
            }
        }
    }
    let mut s = State {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn rel(p: &Path) -> String {
    let root = repo().canonicalize().expect("repo");
    let p = p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
    p.strip_prefix(&root).unwrap_or(&p).display().to_string()
}

#[test]
fn no_import_circles() {
    let found = circles(&import_edges());
    let report: Vec<String> = found
        .iter()
        .map(|set| set.iter().map(|p| rel(p)).collect::<Vec<_>>().join(" ↔ "))
        .collect();
    assert!(report.is_empty(), "{} import circle(s):\n{}", report.len(), report.join("\n"));
}

#[test]
fn no_function_in_lib_over_the_limit() {
    let mut files = Vec::new();
    rust_files(&repo().join("lib"), &mut files);
    let mut long = Vec::new();
    for f in files {
        let src = std::fs::read_to_string(&f).expect("source");
        for (name, line, len) in functions(&tokens(&blank(&src))) {
            if len > MAX_FN_LINES {
                long.push(format!("{}:{line} fn {name}: {len} lines", rel(&f)));
            }
        }
    }
    assert!(
        long.is_empty(),
        "{} function(s) over {MAX_FN_LINES} lines:\n{}",
        long.len(),
        long.join("\n")
    );
}

#[test]
fn no_source_file_over_the_limit() {
    let mut long = Vec::new();
    for dir in crate_dirs().into_iter().chain([repo().join("tests")]) {
        let mut files = Vec::new();
        rust_files(&dir, &mut files);
        for f in files {
            let n = std::fs::read_to_string(&f).expect("source").lines().count();
            if n > MAX_FILE_LINES {
                long.push(format!("{}: {n} lines", rel(&f)));
            }
        }
    }
    long.sort();
    long.dedup();
    assert!(
        long.is_empty(),
        "{} file(s) over {MAX_FILE_LINES} lines:\n{}",
        long.len(),
        long.join("\n")
    );
}

#[test]
fn the_lexer_blanks_comments_strings_and_characters_but_not_lifetimes() {
    let src =
        "fn a<'x>(s: &'x str) -> char { let _ = \"{ // }\"; let _ = r#\"}\"#; /* { */ '{' }\n";
    let toks = tokens(&blank(src));
    let braces =
        toks.iter().filter(|(t, _)| matches!(t, Token::Punct('{') | Token::Punct('}'))).count();
    assert_eq!(braces, 2, "only the body's braces remain");
    assert_eq!(functions(&toks), vec![("a".to_string(), 1, 1)]);
}

#[test]
fn a_use_tree_expands_into_paths() {
    let toks = tokens(&blank("use super::{a::B, c::{D, E as F}, *};\nfn f() { crate::x::y(); }\n"));
    let syn = syntax(&toks);
    let paths: Vec<String> = syn.paths.iter().map(|(_, p)| p.join("::")).collect();
    assert_eq!(paths, ["super::a::B", "super::c::D", "super::c::E", "super", "crate::x::y"]);
}

#[test]
fn two_files_that_import_each_other_are_a_circle() {
    let (a, b, c) = (PathBuf::from("a.rs"), PathBuf::from("b.rs"), PathBuf::from("c.rs"));
    let mut edges = BTreeMap::new();
    edges.insert(a.clone(), BTreeSet::from([b.clone()]));
    edges.insert(b.clone(), BTreeSet::from([a.clone(), c.clone()]));
    edges.insert(c.clone(), BTreeSet::new());
    assert_eq!(circles(&edges), vec![vec![a, b]]);
}
