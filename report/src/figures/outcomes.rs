//! Where the object went, like the paper's Figure 3: for each condition, the outcomes (object x, y)
//! of one representative run (the median run by final KLC, not seed 0) at three epochs, side by
//! side, with the unit disk (the reachable set) and the object's initial position (0.6, 0.6).
//! ArmArrow outcomes are short strokes from the arrow's position to its tip, with a barb at the tip, so the panels
//! show the angle too.

use std::collections::BTreeMap;
use std::path::Path;

use plotters::prelude::*;

use super::{FONT, FigureFile, algo_slot, colour, env_name, file_safe, write_svg};
use crate::aggregate::ConditionSummary;
use crate::error::ReportError;
use crate::load::{Run, Store};
use crate::names::{describe_key, object_word};

const PANEL_W: u32 = 360;
const PANEL_H: u32 = 380;
const TITLE_H: u32 = 34;
/// Opacity of one outcome dot.
const DOT_ALPHA: f64 = 0.6;
/// Length of an ArmArrow outcome's stroke, in world units (the arrow's radius is 10 px of 70).
const STROKE: f64 = 0.08;
/// The object's initial position in both environments (docs/original-code.md section 1).
pub const INITIAL: (f64, f64) = (0.6, 0.6);

/// The run shown for a condition: its median run by final KLC (for an even number of runs the
/// lower of the two middle ones; ties by seed), so the panels show a typical run, not seed 0.
/// Only runs whose outcomes file the store keeps are candidates (`data/results/README.md`);
/// None when there is none.
pub fn representative<'a>(store: &'a Store, c: &ConditionSummary) -> Option<&'a Run> {
    let mut runs: Vec<&Run> = c
        .runs
        .iter()
        .map(|&i| &store.runs[i])
        .filter(|r| r.has_outcomes())
        .collect();
    runs.sort_by(|a, b| {
        a.final_point()
            .klc
            .total_cmp(&b.final_point().klc)
            .then(a.seed.cmp(&b.seed))
            .then(a.campaign.cmp(&b.campaign))
    });
    (!runs.is_empty()).then(|| runs[(runs.len() - 1) / 2])
}

/// The epochs shown for a run whose last epoch is `last`: last/50, last/5 and last
/// (100, 1000, 5000 for the paper's budget), distinct and positive where possible.
pub fn snapshot_epochs(last: i64) -> Vec<i64> {
    let mut e: Vec<i64> = [
        (last as f64 / 50.0).round() as i64,
        (last as f64 / 5.0).round() as i64,
        last,
    ]
    .into_iter()
    .filter(|&e| e > 0 || last == 0)
    .collect();
    e.dedup();
    e
}

/// Outcomes at `epoch` (rows with `epoch <=` it): (episodes, episodes that moved the object).
pub fn counts_at(run: &Run, epoch: i64) -> (usize, usize) {
    let upto = run.outcomes.iter().filter(|o| o.epoch <= epoch);
    let (mut n, mut moved) = (0, 0);
    for o in upto {
        n += 1;
        moved += usize::from(o.moved);
    }
    (n, moved)
}

/// Draws `outcomes_<condition>.svg` for every condition.
pub fn draw_all(
    store: &Store,
    conditions: &[ConditionSummary],
    fig_dir: &Path,
) -> Result<Vec<FigureFile>, ReportError> {
    let mut out = Vec::new();
    for c in conditions {
        let Some(run) = representative(store, c) else {
            continue;
        };
        let last = run
            .outcomes
            .iter()
            .map(|o| o.epoch)
            .max()
            .unwrap_or(0)
            .max(run.final_point().epoch);
        let epochs = snapshot_epochs(last);
        let name = format!("outcomes_{}.svg", file_safe(&c.key.slug()));
        let path = fig_dir.join(&name);
        let col = colour(algo_slot(&c.key.algo, 0));
        let object = object_word(&c.key.env);
        let title = format!(
            "{}, {}: {} positions, median run {} (seed {})",
            env_name(&c.key.env),
            describe_key(&c.key),
            object,
            run.run_id,
            run.seed
        );
        write_svg(
            &path,
            (PANEL_W * epochs.len() as u32, PANEL_H + TITLE_H),
            |root| {
                let area = root.titled(&title, (FONT, 17))?;
                let areas = area.split_evenly((1, epochs.len()));
                for (&e, a) in epochs.iter().zip(areas.iter()) {
                    draw_panel(a, run, e, col, object_word(&c.key.env))?;
                }
                Ok(())
            },
        )?;
        out.push(FigureFile {
            path,
            link: format!("figures/{name}"),
            caption: format!(
                "{}, {}: outcomes of {} at epochs {:?}, the median by final KL-coverage of the {} \
                 of its {} runs whose outcomes file the store keeps",
                env_name(&c.key.env),
                describe_key(&c.key),
                run.run_id,
                epochs,
                c.runs
                    .iter()
                    .filter(|&&i| store.runs[i].has_outcomes())
                    .count(),
                c.runs.len()
            ),
            env: c.key.env.clone(),
        });
    }
    Ok(out)
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    run: &Run,
    epoch: i64,
    col: RGBColor,
    object: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let (n, moved) = counts_at(run, epoch);
    let caption = format!("epoch {epoch}: {moved} of {n} episodes moved the {object}");
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 14))
        .margin(10)
        .x_label_area_size(34)
        .y_label_area_size(40)
        .build_cartesian_2d(-1.1..1.1, -1.1..1.1)?;
    chart
        .configure_mesh()
        .x_desc("x")
        .y_desc("y")
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|v| format!("{v:.1}"))
        .y_label_formatter(&|v| format!("{v:.1}"))
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .max_light_lines(1)
        .light_line_style(RGBColor(0xF2, 0xF2, 0xF2))
        .bold_line_style(RGBColor(0xE2, 0xE2, 0xE2))
        .draw()?;

    // The reachable set: the unit disk.
    chart.draw_series(std::iter::once(PathElement::new(
        super::unit_circle(),
        RGBColor(0x60, 0x60, 0x60).stroke_width(1),
    )))?;

    // Outcomes that land on the same pixel (and, for the arrow, in the same 30° sector of
    // angle) are drawn once, with the opacity of that many stacked marks (1 - (1 - a)^k): the
    // same picture, far fewer SVG elements.
    let mut dots: BTreeMap<(i32, i32, i32), ((f64, f64), Option<f64>, i32)> = BTreeMap::new();
    for o in run.outcomes.iter().filter(|o| o.epoch <= epoch && o.moved) {
        let px = chart.backend_coord(&(o.x, o.y));
        // The arrow's tip points at (angle + 1) pi (the renderer's r = 2 pi (angle + 1) / 2).
        let tip = o.angle.map(|a| (a + 1.0) * std::f64::consts::PI);
        let sector = tip.map_or(0, |t| {
            (t.rem_euclid(std::f64::consts::TAU) / (std::f64::consts::PI / 6.0)).floor() as i32
        });
        let e = dots.entry((px.0, px.1, sector)).or_insert((
            (o.x, o.y),
            tip.map(|_| (f64::from(sector) + 0.5) * std::f64::consts::PI / 6.0),
            0,
        ));
        e.2 += 1;
    }
    for &(at, tip, k) in dots.values() {
        let alpha = 1.0 - (1.0 - DOT_ALPHA).powi(k);
        match tip {
            None => {
                chart.draw_series(std::iter::once(Circle::new(at, 2, col.mix(alpha).filled())))?;
            }
            Some(t) => {
                // A stroke from the position to the tip, with a barb at the tip (one path): the
                // direction reads.
                let end = (at.0 + STROKE * t.cos(), at.1 + STROKE * t.sin());
                let barb = (
                    end.0 - 0.4 * STROKE * (t - 0.6).cos(),
                    end.1 - 0.4 * STROKE * (t - 0.6).sin(),
                );
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![at, end, barb],
                    col.mix(alpha).stroke_width(1),
                )))?;
            }
        }
    }

    // The initial position, where every episode that did not move the object ends.
    chart.draw_series(std::iter::once(
        EmptyElement::at(INITIAL)
            + Circle::new((0, 0), 6, WHITE.filled())
            + Circle::new((0, 0), 6, RED.stroke_width(2))
            + Cross::new((0, 0), 3, RED.stroke_width(2)),
    ))?;
    // Its label outside the disk, with a leader line: the densest data is around the start.
    let label_at = (INITIAL.0 + 0.3, 1.04);
    chart.draw_series(std::iter::once(PathElement::new(
        vec![
            (INITIAL.0 + 0.05, INITIAL.1 + 0.05),
            (label_at.0, label_at.1 - 0.02),
        ],
        RED.stroke_width(1),
    )))?;
    chart.draw_series(std::iter::once(Text::new(
        "start",
        (label_at.0 + 0.02, label_at.1 + 0.06),
        (FONT, 12).into_font().color(&RED),
    )))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gives every run of the store one outcome (as if its outcomes file were kept).
    fn keep_outcomes(store: &mut Store) {
        for r in &mut store.runs {
            r.outcomes = vec![crate::load::Outcome {
                index: 0,
                epoch: 0,
                x: 0.6,
                y: 0.6,
                angle: None,
                moved: false,
            }];
        }
    }

    #[test]
    fn the_representative_run_is_the_median_by_final_klc() {
        let (mut store, conds) =
            crate::claims::tests::synthetic(&[("rge-efr", 0, &[5.0, 3.0, 4.0, 4.5])]);
        // Without any outcomes file there is nothing to draw.
        assert!(representative(&store, &conds[0]).is_none());
        keep_outcomes(&mut store);
        // Final KLC 3.0 (seed 1), 4.0 (seed 2), 4.5 (seed 3), 5.0 (seed 0): the lower middle.
        assert_eq!(representative(&store, &conds[0]).unwrap().seed, 2);
        // Among the runs whose outcomes are kept only: without seed 2's, 3.0 / 4.5 / 5.0.
        store.runs[2].outcomes.clear();
        assert_eq!(representative(&store, &conds[0]).unwrap().seed, 3);
        let (mut store, conds) =
            crate::claims::tests::synthetic(&[("rge-efr", 0, &[5.0, 3.0, 4.0])]);
        keep_outcomes(&mut store);
        assert_eq!(representative(&store, &conds[0]).unwrap().seed, 2);
    }

    #[test]
    fn snapshot_epochs_follow_the_paper_for_its_budget() {
        assert_eq!(snapshot_epochs(5000), vec![100, 1000, 5000]);
        assert_eq!(snapshot_epochs(500), vec![10, 100, 500]);
        assert_eq!(snapshot_epochs(10), vec![2, 10]);
        assert_eq!(snapshot_epochs(0), vec![0]);
    }
}
