//! Code that reaches a result file computes transcendental functions with the `libm` crate, not
//! the platform's libm (whose variants are chosen by CPU feature): outside test modules, no
//! `.exp()`, `.ln()`, `.sin()`, ... method call on a float, nor its function form (`f64::exp(x)`),
//! in `benchmark/src`, `types/src`, `kernels/src`, `env/src` (rollouts and pictures) or
//! `python/src`, and none of burn's transcendental tensor operations (`.exp()`, `.log()`,
//! `.powf_scalar(`, its activations other than `relu`): the networks' latent middle computes
//! them by `repr/host_ops.rs`. The report (`report/src`) is not result code: its statistics and
//! figures use the platform's functions (`docs/reproducibility.md`).

use std::path::Path;

const METHODS: [&str; 15] = [
    ".exp(",
    ".log(",
    ".log1p(",
    ".powf_scalar(",
    ".powi_scalar(",
    ".ln(",
    ".ln_1p(",
    ".exp_m1(",
    ".sin(",
    ".cos(",
    ".sin_cos(",
    ".tanh(",
    ".powf(",
    ".atan2(",
    ".hypot(",
];

/// The offending lines of one source file (`path:line: text`), test modules left out.
fn offending(path: &Path, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let code = line.split("//").next().unwrap_or("");
        if line.trim_start().starts_with("//") {
            continue;
        }
        let burn_activation = code.contains("activation::") && !code.contains("activation::relu");
        // `f64::exp(x)` is the same platform call as `x.exp()`.
        let function_form = METHODS.iter().any(|m| {
            let name = &m[1..];
            code.contains(&format!("f64::{name}")) || code.contains(&format!("f32::{name}"))
        });
        if burn_activation || function_form || METHODS.iter().any(|m| code.contains(m)) {
            out.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
        }
    }
    out
}

fn walk(dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            walk(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.extend(offending(&p, &std::fs::read_to_string(&p).unwrap()));
        }
    }
}

#[test]
fn result_code_uses_libm_for_transcendental_functions() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = Vec::new();
    for dir in [
        "benchmark/src",
        "types/src",
        "kernels/src",
        "env/src",
        "python/src",
    ] {
        walk(&root.join(dir), &mut found);
    }
    assert!(
        found.is_empty(),
        "platform transcendental functions in result code (use libm::...): {found:#?}"
    );
}

#[test]
fn the_check_finds_a_platform_call() {
    let planted = "fn f(x: f64) -> f64 {\n    x.exp() + libm::log(x)\n}\n";
    assert_eq!(offending(Path::new("x.rs"), planted).len(), 1);
    let function_form = "let y = f64::ln(x) * f32::cos(t) as f64;\n";
    assert_eq!(offending(Path::new("x.rs"), function_form).len(), 1);
    let libm_call = "let y = libm::exp(x) + libm::cosf(t) as f64;\n";
    assert!(offending(Path::new("x.rs"), libm_call).is_empty());
    let tensor = "let z = e.mul(v.exp()); // burn tensor op\n";
    assert_eq!(offending(Path::new("x.rs"), tensor).len(), 1);
    let activation = "use burn::tensor::activation::sigmoid;\n";
    assert_eq!(offending(Path::new("x.rs"), activation).len(), 1);
    let relu = "use burn::tensor::activation::relu;\n";
    assert!(offending(Path::new("x.rs"), relu).is_empty());
    let in_tests = "#[cfg(test)]\nmod tests { fn g() { 2f64.ln(); } }\n";
    assert!(offending(Path::new("x.rs"), in_tests).is_empty());
}
