//! Renders a report from any store, e.g. to look at the figures of a small store:
//!
//! `cargo run -p ugl-report --example render -- RESULTS OUT [MAIN_CAMPAIGN]`
//!
//! (the `ugl report` command is the normal way; this one takes the main campaign as an argument
//! and uses 2,000 bootstrap resamples, enough to look at.)

use std::path::PathBuf;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: render RESULTS OUT [MAIN_CAMPAIGN]");
        std::process::exit(2);
    }
    let mut opts = ugl_report::ReportOptions::new(PathBuf::from(&args[0]), PathBuf::from(&args[1]));
    if let Some(main) = args.get(2) {
        opts.main_campaign = main.clone();
    }
    opts.paper_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
    opts.n_boot = 2_000;
    match ugl_report::render_report(&opts) {
        Ok(s) => println!(
            "{} runs ({} main), {} files; budget {:?}; unused {:?}",
            s.n_runs,
            s.n_main_runs,
            s.files.len(),
            s.budget_campaigns,
            s.unused_campaigns
        ),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
