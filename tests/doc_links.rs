//! The README is a front page and its chapters live in `docs/`: every relative link and image in
//! `README.md` and `docs/*.md` must lead to a file that exists (and a `#anchor` to a heading of
//! that file), the front page must stay short, and every chapter's code blocks must be compiled as
//! doctests (listed in `src/lib.rs`). A constant's rustdoc is a rule and its reason: no paragraph
//! of it longer than [`CONST_DOC_MAX_LINES`] lines (measurements live in `docs/` and
//! CHANGELOG.md). Pure file reading: no network, no build of the docs.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// The front page's budget, in lines.
const README_MAX_LINES: usize = 400;

/// The longest paragraph a constant's rustdoc may have, in lines.
const CONST_DOC_MAX_LINES: usize = 6;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `README.md` and every `docs/*.md`, sorted.
fn markdown_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = fs::read_dir(root().join("docs"))
        .expect("docs/ exists")
        .map(|e| e.expect("a readable docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

/// Whether a line opens or closes a fenced code block.
fn is_fence(line: &str) -> bool {
    let trimmed = line.trim_start();
    trimmed.starts_with("```") || trimmed.starts_with("~~~")
}

/// The lines of a markdown text outside fenced code blocks, numbered from 1, with inline code
/// spans removed.
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fence = false;
    for (i, line) in text.lines().enumerate() {
        if is_fence(line) {
            fence = !fence;
        } else if !fence {
            out.push((i + 1, strip_code_spans(line)));
        }
    }
    out
}

/// The line without its `code spans` (a link inside backticks is text, not a link).
fn strip_code_spans(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find('`') {
        out.push_str(&rest[..start]);
        let ticks = rest[start..].chars().take_while(|&c| c == '`').count();
        let after = &rest[start + ticks..];
        match after.find(&"`".repeat(ticks)) {
            Some(end) => rest = &after[end + ticks..],
            None => {
                rest = after;
                break;
            }
        }
    }
    out.push_str(rest);
    out
}

/// The targets of inline links and images, `[text](target)` and `![alt](target "title")`, and
/// of reference definitions, `[label]: target`.
fn link_targets(line: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let bytes = line.as_bytes();
    let mut i = 0;
    while let Some(off) = line[i..].find("](") {
        let start = i + off + 2;
        // The target ends at the matching `)`, balancing parentheses inside it.
        let mut depth = 1;
        let mut end = start;
        while end < bytes.len() {
            match bytes[end] {
                b'(' => depth += 1,
                b')' => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                _ => {}
            }
            end += 1;
        }
        let raw = line[start..end.min(bytes.len())].trim();
        let raw = raw.trim_start_matches('<');
        let target = raw.split([' ', '>']).next().unwrap_or("");
        targets.push(target.to_string());
        i = end.min(bytes.len());
    }
    let trimmed = line.trim_start();
    if trimmed.starts_with('[')
        && let Some(close) = trimmed.find("]:")
    {
        let target = trimmed[close + 2..].split_whitespace().next().unwrap_or("");
        targets.push(target.to_string());
    }
    targets
}

/// Whether a target leaves the repository (a web address, mail) and so is not checked here.
fn is_external(target: &str) -> bool {
    target.contains("://") || target.starts_with("mailto:")
}

/// GitHub's anchor for a heading: lower case, spaces to `-`, every character that is not a
/// letter, digit, `-` or `_` dropped (code spans keep their text, the backticks go).
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a markdown file's headings, with GitHub's `-1`, `-2` for repeated ones.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut fence = false;
    for line in text.lines() {
        if is_fence(line) {
            fence = !fence;
            continue;
        }
        if fence || !line.starts_with('#') {
            continue;
        }
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if hashes > 6 || !line[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(&line[hashes..]);
        let mut anchor = base.clone();
        let mut n = 0;
        while seen.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        seen.insert(anchor);
    }
    seen
}

/// Every broken relative link of one markdown file, as `file:line: target: reason`, and how many
/// relative links it checked.
fn broken_links(file: &Path) -> (Vec<String>, usize) {
    let text = fs::read_to_string(file).expect("a readable markdown file");
    let dir = file.parent().expect("a file has a folder");
    let name = file.strip_prefix(root()).unwrap_or(file).display();
    let mut broken = Vec::new();
    let mut checked = 0;
    for (n, line) in prose_lines(&text) {
        for target in link_targets(&line) {
            if target.is_empty() {
                broken.push(format!("{name}:{n}: empty link target"));
                continue;
            }
            if is_external(&target) {
                continue;
            }
            checked += 1;
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let linked = if path.is_empty() {
                file.to_path_buf()
            } else {
                dir.join(path)
            };
            if !linked.exists() {
                broken.push(format!(
                    "{name}:{n}: `{target}`: no file {}",
                    linked.display()
                ));
                continue;
            }
            if let Some(anchor) = anchor
                && linked.extension().is_some_and(|x| x == "md")
            {
                let headings = anchors(&fs::read_to_string(&linked).expect("a readable file"));
                if !headings.contains(anchor) {
                    let within = if path.is_empty() { "this file" } else { path };
                    broken.push(format!(
                        "{name}:{n}: `{target}`: no heading with anchor `#{anchor}` in {within}"
                    ));
                }
            }
        }
    }
    (broken, checked)
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut entries: Vec<PathBuf> = fs::read_dir(dir)
        .expect("a readable folder")
        .map(|e| e.expect("a readable entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|x| x == "rs") {
            files.push(path);
        }
    }
    files
}

/// Whether a line declares a constant (`const X: T`, `pub const`, `pub(crate) const`; not a
/// `const fn`).
fn declares_const(line: &str) -> bool {
    let mut rest = line.trim_start();
    if let Some(r) = rest.strip_prefix("pub") {
        rest = match r.strip_prefix('(') {
            Some(r) => r.split_once(')').map_or(r, |(_, after)| after),
            None => r,
        }
        .trim_start();
    }
    let Some(r) = rest.strip_prefix("const ") else {
        return false;
    };
    let name: String = r
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect();
    !name.is_empty() && name != "fn" && r.trim_start()[name.len()..].trim_start().starts_with(':')
}

/// The constants of `text` whose rustdoc (the `///` lines directly above, attributes skipped)
/// has a paragraph longer than `max` lines: (line of the constant, longest paragraph).
fn long_const_docs(text: &str, max: usize) -> Vec<(usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut long = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if !declares_const(line) {
            continue;
        }
        let mut j = i;
        while j > 0 && lines[j - 1].trim_start().starts_with("#[") {
            j -= 1;
        }
        let (mut longest, mut run) = (0, 0);
        while j > 0 && lines[j - 1].trim_start().starts_with("///") {
            j -= 1;
            if lines[j].trim_start()[3..].trim().is_empty() {
                run = 0;
            } else {
                run += 1;
                longest = longest.max(run);
            }
        }
        if longest > max {
            long.push((i + 1, longest));
        }
    }
    long
}

#[test]
fn constant_docs_are_rules_not_histories() {
    let mut long = Vec::new();
    let mut constants = 0;
    for file in rust_files(&root().join("src")) {
        let text = fs::read_to_string(&file).unwrap();
        constants += text.lines().filter(|l| declares_const(l)).count();
        for (line, n) in long_const_docs(&text, CONST_DOC_MAX_LINES) {
            long.push(format!(
                "{}:{line}: a paragraph of {n} lines",
                file.strip_prefix(root()).unwrap_or(&file).display()
            ));
        }
    }
    assert!(
        long.is_empty(),
        "constants' rustdoc with a paragraph longer than {CONST_DOC_MAX_LINES} lines (state the \
         rule and its reason; measurements go to docs/ and CHANGELOG.md):\n{}",
        long.join("\n")
    );
    // A scanner that finds nothing checks nothing.
    assert!(
        constants >= 50,
        "only {constants} constants found under src/"
    );
}

#[test]
fn every_relative_link_and_image_of_the_docs_resolves() {
    let files = markdown_files();
    assert!(files.len() > 2, "README.md and its chapters in docs/");
    let mut broken = Vec::new();
    let mut checked = 0;
    for file in &files {
        let (b, c) = broken_links(file);
        broken.extend(b);
        checked += c;
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
    // The front page alone links every chapter: a parser that finds nothing checks nothing.
    assert!(checked >= 20, "only {checked} relative links found");
}

#[test]
fn the_readme_is_a_front_page() {
    let text = fs::read_to_string(root().join("README.md")).unwrap();
    let lines = text.lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines, more than the front page's {README_MAX_LINES}: move the detail into a chapter in docs/"
    );
    // Every chapter is reachable from the front page.
    for file in markdown_files().iter().skip(1) {
        let chapter = format!("docs/{}", file.file_name().unwrap().to_string_lossy());
        assert!(
            text.contains(&format!("]({chapter}")),
            "README.md links no chapter {chapter}"
        );
    }
}

#[test]
fn every_chapter_is_compiled_as_doctests() {
    let lib = fs::read_to_string(root().join("src/lib.rs")).unwrap();
    for file in markdown_files().iter().skip(1) {
        let name = file.file_name().unwrap().to_string_lossy();
        if name == "MODEL.md" {
            // The `model` module's own doc (src/model/mod.rs).
            continue;
        }
        assert!(
            lib.contains(&format!("include_str!(\"../docs/{name}\")")),
            "docs/{name} is not included in src/lib.rs as doctests: its code blocks would go unchecked"
        );
    }
}

#[test]
fn the_checker_finds_what_it_should() {
    // Links inside code are text; web addresses are not checked; anchors follow GitHub.
    assert_eq!(
        link_targets(&strip_code_spans(
            "see `[a](nowhere.md)` and [b](docs/x.md#y)"
        )),
        ["docs/x.md#y"]
    );
    assert_eq!(
        link_targets("![fig](figures/a.png \"title\") [w](https://rapier.rs)"),
        ["figures/a.png", "https://rapier.rs"]
    );
    assert_eq!(link_targets("[f](a_(b).md)"), ["a_(b).md"]);
    assert_eq!(link_targets("[label]: docs/x.md"), ["docs/x.md"]);
    assert_eq!(
        slug(" The large-step model (game and robot rates)"),
        "the-large-step-model-game-and-robot-rates"
    );
    assert_eq!(
        slug(" The paper's studies: results"),
        "the-papers-studies-results"
    );
    assert_eq!(
        slug(" bevy_ecs (feature `ecs`, on by default)"),
        "bevy_ecs-feature-ecs-on-by-default"
    );
    let headings = anchors("# A\n## A\n```\n# not a heading\n```\n#no\n");
    assert_eq!(
        headings,
        BTreeSet::from(["a".to_string(), "a-1".to_string()])
    );
    assert!(declares_const(
        "    pub const FILE: &'static str = \".lock\";"
    ));
    assert!(declares_const("pub(crate) const X: f64 = 1.0;"));
    assert!(!declares_const("pub const fn new() -> Self {"));
    assert!(!declares_const("// const X: f64"));
    let doc = "/// a\n/// b\n///\n/// c\n/// d\n/// e\n#[doc(hidden)]\nconst X: u8 = 0;\n";
    assert!(long_const_docs(doc, 3).is_empty());
    assert_eq!(long_const_docs(doc, 2), [(8, 3)]);
    let lines = prose_lines("text\n```rust\n[x](gone.md)\n```\n[y](here.md)\n");
    assert_eq!(lines.len(), 2);
    assert_eq!(link_targets(&lines[1].1), ["here.md"]);
}
