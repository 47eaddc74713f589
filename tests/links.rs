//! The user-facing markdown points only at things a fresh clone has: every relative link and every
//! back-quoted repository path resolves, and no page cites notes that live outside the repository.
//!
//! Checked: `README.md`, `docs/*.md`, `report/out/*.md` (generated: fix the string in
//! `report/src` that writes a broken reference, then `make report`), `report/README.md`,
//! `data/*/README.md` and `scripts/README*.md`.

use std::path::{Path, PathBuf};

/// File names of notes that were never part of the repository, so a user cannot follow a
/// citation of them. Spelt in pieces so that a search of the repository for these names finds
/// only the pages that cite them, not this check.
const OUTSIDE_NOTES: [&str; 5] = [
    concat!("PAPER", "-NOTES"),
    concat!("DESIGN", ".md"),
    concat!("STACK", "-NOTES"),
    concat!("/wo", "rk/"),
    concat!("../sha", "red"),
];

/// How a back-quoted repository path starts.
const REPO_PREFIXES: [&str; 12] = [
    "README.md",
    "docs/",
    "data/",
    "report/",
    "benchmark/",
    "types/",
    "src/",
    "scripts/",
    "tests/",
    "Makefile",
    "Cargo.toml",
    ".ci/",
];

/// Upper-case words that are real file names, not placeholders such as `NAME`, `OUT` or `DIR`.
const UPPER_CASE_FILE_NAMES: [&str; 2] = ["README", "REPORT"];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The markdown files of `dir` (relative to the root) whose names satisfy `keep`, sorted.
fn markdown_in(dir: &str, keep: impl Fn(&str) -> bool) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(&keep))
        .map(|p| p.strip_prefix(root()).unwrap().to_path_buf())
        .collect();
    v.sort();
    v
}

/// Every checked page, relative to the root.
fn documents() -> Vec<PathBuf> {
    let md = |n: &str| n.ends_with(".md");
    let mut v = vec![
        PathBuf::from("README.md"),
        PathBuf::from("report/README.md"),
    ];
    v.extend(markdown_in("docs", md));
    v.extend(markdown_in("report/out", md));
    v.extend(markdown_in("scripts", |n| {
        n.starts_with("README") && n.ends_with(".md")
    }));
    let mut data: Vec<PathBuf> = std::fs::read_dir(root().join("data"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("README.md").is_file())
        .map(|p| p.strip_prefix(root()).unwrap().join("README.md"))
        .collect();
    data.sort();
    v.extend(data);
    v
}

/// A reference found in a page, at a 1-based line.
struct Found {
    line: usize,
    text: String,
}

/// The references of one markdown text: relative link targets and code spans, outside fenced
/// code blocks.
#[derive(Default)]
struct Parsed {
    links: Vec<Found>,
    spans: Vec<Found>,
}

fn parse(text: &str) -> Parsed {
    // Blank out fenced code blocks (keeping the line breaks, so that offsets keep their lines).
    let mut masked = String::with_capacity(text.len());
    let mut fence: Option<&str> = None;
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        let marker = ["```", "~~~"].into_iter().find(|m| t.starts_with(*m));
        let in_code = match (fence, marker) {
            (None, Some(m)) => {
                fence = Some(m);
                true
            }
            (Some(f), Some(m)) if f == m => {
                fence = None;
                true
            }
            (Some(_), _) => true,
            (None, None) => false,
        };
        if in_code {
            masked.push_str(if line.ends_with('\n') { "\n" } else { "" });
        } else {
            masked.push_str(line);
        }
    }
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(masked.match_indices('\n').map(|(k, _)| k + 1))
        .collect();
    let line_of = |offset: usize| line_starts.partition_point(|&s| s <= offset);

    // Code spans: a run of n backticks up to the next run of exactly n; the prose keeps the rest.
    let bytes = masked.as_bytes();
    let mut parsed = Parsed::default();
    let mut prose = bytes.to_vec();
    let run_at = |i: usize| bytes[i..].iter().take_while(|&&b| b == b'`').count();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] != b'`' {
            i += 1;
            continue;
        }
        let n = run_at(i);
        let mut j = i + n;
        let mut close = None;
        while j < bytes.len() {
            if bytes[j] == b'`' {
                let m = run_at(j);
                if m == n {
                    close = Some(j);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(j) => {
                let content = masked[i + n..j].replace('\n', " ");
                parsed.spans.push(Found {
                    line: line_of(i),
                    text: content.trim().to_string(),
                });
                for b in &mut prose[i..j + n] {
                    if *b != b'\n' {
                        *b = b' ';
                    }
                }
                i = j + n;
            }
            None => i += n,
        }
    }

    // Links `[text](target)` and images `![alt](target)` in the prose.
    let prose = String::from_utf8(prose).expect("only ASCII bytes were replaced");
    let mut from = 0;
    while let Some(k) = prose[from..].find("](") {
        let start = from + k + 2;
        let rest = &prose[start..];
        let target = match rest.strip_prefix('<') {
            Some(r) => r.split('>').next().unwrap_or(""),
            None => rest
                .split(|c: char| c == ')' || c.is_whitespace())
                .next()
                .unwrap_or(""),
        };
        parsed.links.push(Found {
            line: line_of(start),
            text: target.to_string(),
        });
        from = start;
    }
    parsed
}

/// The file a relative link points at, or `None` for links that leave the repository (web,
/// mail) or stay on the page.
fn link_path(target: &str) -> Option<&str> {
    let skip = ["http://", "https://", "mailto:", "#"];
    if target.is_empty() || skip.iter().any(|s| target.starts_with(s)) {
        return None;
    }
    Some(target.split('#').next().unwrap())
}

/// The repository path a code span names, or `None` when it is not one: it must start like a
/// path of the repository and hold no spaces, globs, templates or placeholders (`NAME.toml`).
/// A trailing `:line` or `#anchor` is dropped.
fn span_path(span: &str) -> Option<&str> {
    if !REPO_PREFIXES.iter().any(|p| span.starts_with(p)) {
        return None;
    }
    if span.contains([' ', '*', '<', '>', '{', '}', '$']) {
        return None;
    }
    let placeholder = span.split(['/', '.', '-', '_']).any(|w| {
        w.starts_with(|c: char| c.is_ascii_uppercase())
            && w.chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
            && !UPPER_CASE_FILE_NAMES.contains(&w)
    });
    if placeholder {
        return None;
    }
    let path = span.split('#').next().unwrap();
    match path.rsplit_once(':') {
        Some((head, tail))
            if !tail.is_empty() && tail.chars().all(|c| c.is_ascii_digit() || c == '-') =>
        {
            Some(head)
        }
        _ => Some(path),
    }
}

/// Paths that the code creates at run time and git ignores (`.gitignore`): a page may name them,
/// but a fresh clone does not have them, so they are not looked for.
fn made_at_run_time(path: &str) -> bool {
    let parts: Vec<&str> = path.split('/').collect();
    let store =
        parts.len() >= 4 && parts[0] == "data" && matches!(parts[1], "results" | "results-pending");
    (store && parts[3] == "models") || path.ends_with(".ugl-store.lock")
}

#[test]
fn parser_finds_links_spans_and_skips_code_blocks() {
    let text = "See [a](docs/a.md#x), [web](https://x.org) and `docs/b.md:12`,\n\
                ``data/`c` `` and a span `over\nlines`.\n\
                ```\n[not](a link) `not/a span`\n```\n\
                ![img](figures/f.svg \"title\") `report/NAME.md` `tests/*.rs`\n";
    let p = parse(text);
    let links: Vec<(usize, &str)> = p.links.iter().map(|f| (f.line, f.text.as_str())).collect();
    assert_eq!(
        links,
        [
            (1, "docs/a.md#x"),
            (1, "https://x.org"),
            (7, "figures/f.svg")
        ]
    );
    let spans: Vec<(usize, &str)> = p.spans.iter().map(|f| (f.line, f.text.as_str())).collect();
    assert_eq!(
        spans,
        [
            (1, "docs/b.md:12"),
            (2, "data/`c`"),
            (2, "over lines"),
            (7, "report/NAME.md"),
            (7, "tests/*.rs")
        ]
    );
    assert_eq!(link_path("docs/a.md#x"), Some("docs/a.md"));
    assert_eq!(link_path("https://x.org"), None);
    assert_eq!(link_path("#section"), None);
    assert_eq!(span_path("docs/b.md:12"), Some("docs/b.md"));
    assert_eq!(span_path("README.md#building"), Some("README.md"));
    assert_eq!(
        span_path("report/out/REPORT.md"),
        Some("report/out/REPORT.md")
    );
    assert_eq!(span_path("report/NAME.md"), None);
    assert_eq!(span_path("tests/*.rs"), None);
    assert_eq!(span_path("ugl run --env armball"), None);
    assert!(made_at_run_time("data/results/paper/models/x.model"));
    assert!(!made_at_run_time("data/results/paper/campaign.toml"));
}

#[test]
fn documentation_references_resolve() {
    let report_out = root().join("report/out");
    let mut broken = Vec::new();
    let (mut links, mut paths) = (0, 0);
    for doc in documents() {
        let text = std::fs::read_to_string(root().join(&doc))
            .unwrap_or_else(|e| panic!("{}: {e}", doc.display()));
        let name = doc.display();
        for (n, line) in text.lines().enumerate() {
            for needle in OUTSIDE_NOTES {
                if line.contains(needle) {
                    broken.push(format!(
                        "{name}:{}: {needle} (not in the repository)",
                        n + 1
                    ));
                }
            }
        }
        let parsed = parse(&text);
        let dir = root().join(&doc).parent().unwrap().to_path_buf();
        for f in &parsed.links {
            let Some(target) = link_path(&f.text) else {
                continue;
            };
            links += 1;
            if !dir.join(target).exists() {
                broken.push(format!(
                    "{name}:{}: ({}) (link target not found)",
                    f.line, f.text
                ));
            }
        }
        for f in &parsed.spans {
            let Some(path) = span_path(&f.text) else {
                continue;
            };
            if made_at_run_time(path) {
                continue;
            }
            paths += 1;
            let found = root().join(path).exists()
                || (doc.starts_with("report/out") && report_out.join(path).exists());
            if !found {
                broken.push(format!("{name}:{}: `{}` (no such path)", f.line, f.text));
            }
        }
    }
    assert!(
        broken.is_empty(),
        "{} broken references in the documentation:\n{}",
        broken.len(),
        broken.join("\n")
    );
    // A parser that found nothing would pass vacuously.
    assert!(
        links >= 20 && paths >= 100,
        "only {links} links and {paths} paths checked"
    );
}
