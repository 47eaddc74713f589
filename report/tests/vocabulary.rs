//! The report speaks the vocabulary through `ugl-types`' registries, never by spelling it: outside
//! test code, no string literal in `report/src` is the name of a learner, an algorithm, a goal
//! sampler or a variant. (`none`, a sampler and a variant but also an English word, is left out.)

use std::path::{Path, PathBuf};

fn vocabulary() -> Vec<&'static str> {
    let mut v: Vec<&'static str> = Vec::new();
    for l in ugl_types::LearnerInfo::all() {
        v.extend([l.name, l.algo]);
    }
    v.extend(ugl_types::StrategyInfo::all().map(|s| s.algo));
    v.extend(ugl_types::SamplerInfo::all().map(|s| s.name));
    v.extend(ugl_types::VariantInfo::all().map(|s| s.name));
    v.retain(|w| *w != "none");
    v
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The file's lines outside test code: an item under `#[cfg(test)]` at the top level runs to
/// its closing brace in column 0.
fn production_lines(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut in_test = false;
    for (i, line) in text.lines().enumerate() {
        if line.starts_with("#[cfg(test)]") {
            in_test = true;
            continue;
        }
        if in_test {
            if line == "}" {
                in_test = false;
            }
            continue;
        }
        if !line.trim_start().starts_with("//") {
            out.push((i + 1, line));
        }
    }
    out
}

/// The string literals of a line (no escapes in the words looked for).
fn literals(line: &str) -> Vec<&str> {
    line.split('"').skip(1).step_by(2).collect()
}

#[test]
fn no_report_code_spells_a_learner_sampler_variant_or_algorithm() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let words = vocabulary();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    assert!(files.len() > 20, "report/src not found: {}", src.display());
    let mut found = Vec::new();
    for f in &files {
        let rel = f
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let text = std::fs::read_to_string(f).unwrap();
        for (n, line) in production_lines(&text) {
            for lit in literals(line) {
                if words.contains(&lit) {
                    found.push(format!("{rel}:{n}: \"{lit}\""));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "name these through ugl-types (Algo, Sampler, Variant, the registries), not by spelling:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_finds_a_spelt_name() {
    let code = "fn f(k: &Key) -> bool {\n    k.sampler == \"gaussian\"\n}\n#[cfg(test)]\nmod tests {\n    const X: &str = \"kde\";\n}\n";
    let words = vocabulary();
    let hits: Vec<&str> = production_lines(code)
        .into_iter()
        .flat_map(|(_, l)| literals(l))
        .filter(|l| words.contains(l))
        .collect();
    assert_eq!(hits, ["gaussian"]);
}
