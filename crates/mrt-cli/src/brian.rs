//! `mrt brian check|eval|plot`: Mr. BRIAN's checker (MRT manual §10.4.7), a JSON Lines
//! evaluator, and a drawing of every shape.

use anyhow::{anyhow, bail, Context as _, Result};
use mrt_fuzzy::brian::Brian;
use mrt_fuzzy::FuzzySet;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::io::{BufRead, Write};
use std::path::Path;

/// `mrt brian check DIR`: silent when the configuration is correct (like the manual's checker)
/// but for warnings (unused definitions); on an error, the error and exit status 1.
pub fn check(dir: &Path) -> Result<()> {
    match Brian::from_dir(dir) {
        Ok(b) => {
            for w in b.warnings() {
                eprintln!("{}", mrt_core::printable(&w.to_string()));
            }
            Ok(())
        }
        Err(e) => {
            eprintln!("{}", mrt_core::printable(&e.to_string()));
            std::process::exit(1);
        }
    }
}

fn parse_cycle(line: &str, n: usize) -> Result<Vec<(String, f64, f64)>> {
    let obj: Map<String, Value> = serde_json::from_str(line)
        .with_context(|| format!("input line {n} is not a JSON object"))?;
    obj.into_iter()
        .map(|(k, v)| {
            let (value, rel) = match &v {
                Value::Number(x) => (x.as_f64(), Some(1.0)),
                Value::Array(a) if a.len() == 1 || a.len() == 2 => {
                    (a[0].as_f64(), a.get(1).map_or(Some(1.0), Value::as_f64))
                }
                _ => (None, None),
            };
            match (value, rel) {
                (Some(v), Some(r)) => Ok((k, v, r)),
                _ => bail!(
                    "input line {n}: `{k}` must be a number or [value, reliability], found {v}"
                ),
            }
        })
        .collect()
}

fn fv(v: mrt_fuzzy::FuzzyValue) -> Value {
    json!([v.value, v.reliability])
}

/// `mrt brian eval DIR [--input FILE] [--trace] [--semantics manual|original]`: one JSON
/// object of commands per input line.
pub fn eval(dir: &Path, input: Option<&Path>, trace: bool, semantics: Option<&str>) -> Result<()> {
    let mut brian = Brian::from_dir(dir)?;
    if let Some(name) = semantics {
        let s =
            mrt_fuzzy::engine::semantics_by_name(name).map_err(|e| anyhow!("--semantics: {e}"))?;
        brian.set_semantics(s);
    }
    brian.set_tracing(trace);
    let reader: Box<dyn BufRead> = match input {
        Some(p) => Box::new(std::io::BufReader::new(
            std::fs::File::open(p).with_context(|| format!("cannot open {}", p.display()))?,
        )),
        None => Box::new(std::io::BufReader::new(std::io::stdin())),
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    for (i, line) in reader.lines().enumerate() {
        let line = line.context("cannot read the input")?;
        if line.trim().is_empty() {
            continue;
        }
        let owned = parse_cycle(&line, i + 1)?;
        let args: Vec<(&str, f64, f64)> =
            owned.iter().map(|(k, v, r)| (k.as_str(), *v, *r)).collect();
        let commands = brian.run(&args);
        // Commands iterate in name order: keys come out sorted.
        let mut obj: Map<String, Value> =
            commands.iter().map(|(k, v)| (k.to_string(), json!(v))).collect();
        if trace {
            let t = brian.trace();
            let preds: Map<String, Value> =
                t.predicates.iter().map(|(n, v)| (n.to_string(), fv(*v))).collect();
            let acts: Map<String, Value> =
                t.predicate_actions.iter().map(|(n, v)| (n.to_string(), fv(*v))).collect();
            let behs: Map<String, Value> = t
                .behaviors
                .iter()
                .map(|(n, level, a)| {
                    let v = match a {
                        Some((c, w)) => {
                            json!({"level": level, "active": true, "cando": fv(*c), "want": fv(*w)})
                        }
                        None => json!({"level": level, "active": false}),
                    };
                    (n.to_string(), v)
                })
                .collect();
            let proposals: Vec<Value> = t
                .proposals
                .iter()
                .map(|p| match p.value {
                    Some(v) => json!({"behavior": p.behavior, "action": p.action, "label": p.label, "value": v}),
                    None => json!({"behavior": p.behavior, "action": p.action, "delete": p.label.unwrap_or("ANY")}),
                })
                .collect();
            obj.insert(
                "_trace".into(),
                json!({"predicates": preds, "predicate_actions": acts, "behaviors": behs, "proposals": proposals}),
            );
        }
        writeln!(out, "{}", Value::Object(obj))?;
    }
    out.flush()?;
    Ok(())
}

const COLORS: [&str; 8] =
    ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// One panel: sets as `(label, polyline points or a singleton x)`.
fn panel(svg: &mut String, y0: f64, title: &str, sets: &[(String, FuzzySet)]) {
    let (w, h, left) = (760.0, 120.0, 60.0);
    let params: Vec<f64> =
        sets.iter().flat_map(|(_, s)| s.params()).filter(|p| p.is_finite()).collect();
    let (mut lo, mut hi) =
        params.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(*p), b.max(*p)));
    if lo > hi {
        (lo, hi) = (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.1).max(1.0);
    let (lo, hi) = (lo - pad, hi + pad);
    let x = |v: f64| left + (v - lo) / (hi - lo) * w;
    let y = |m: f64| y0 + 52.0 + (1.0 - m) * h;
    let _ = writeln!(
        svg,
        r#"<text x="{left}" y="{}" font-weight="bold">{}</text>"#,
        y0 + 18.0,
        esc(title)
    );
    let _ = writeln!(
        svg,
        r##"<line x1="{left}" y1="{}" x2="{}" y2="{}" stroke="#888"/>"##,
        y(0.0),
        left + w,
        y(0.0)
    );
    let _ = writeln!(
        svg,
        r##"<line x1="{left}" y1="{}" x2="{left}" y2="{}" stroke="#888"/>"##,
        y(0.0),
        y(1.0)
    );
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" font-size="10" text-anchor="middle">{lo:.1}</text><text x="{}" y="{}" font-size="10" text-anchor="middle">{hi:.1}</text>"#,
        left,
        y(0.0) + 12.0,
        left + w,
        y(0.0) + 12.0
    );
    for (k, (label, set)) in sets.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let (peak_x, points) = match set {
            FuzzySet::Sng { a } => {
                let _ = writeln!(
                    svg,
                    r#"<line x1="{0}" y1="{1}" x2="{0}" y2="{2}" stroke="{color}" stroke-width="2"/>"#,
                    x(*a),
                    y(0.0),
                    y(1.0)
                );
                (*a, None)
            }
            _ => {
                let n = 600;
                let mut pts = String::new();
                let mut best = (lo, -1.0);
                for i in 0..=n {
                    let v = lo + (hi - lo) * f64::from(i) / f64::from(n);
                    let m = set.membership(v);
                    if m > best.1 {
                        best = (v, m);
                    }
                    let _ = write!(pts, "{:.1},{:.1} ", x(v), y(m));
                }
                (best.0, Some(pts))
            }
        };
        if let Some(pts) = points {
            let _ = writeln!(
                svg,
                r#"<polyline fill="none" stroke="{color}" stroke-width="2" points="{pts}"/>"#
            );
        }
        let _ = writeln!(
            svg,
            r#"<text x="{}" y="{}" font-size="11" fill="{color}" text-anchor="middle">{}</text>"#,
            x(peak_x),
            y(1.0) - 4.0 - 11.0 * (k % 2) as f64,
            esc(label)
        );
    }
}

/// `mrt brian plot DIR --out FILE.svg`: every input and output shape, one panel each.
pub fn plot(dir: &Path, out: &Path) -> Result<()> {
    let brian = Brian::from_dir(dir)?;
    let mut body = String::new();
    let mut y0 = 0.0;
    for (name, shape) in brian.input_shapes() {
        panel(&mut body, y0, &format!("input {name} — shape {}", shape.name), &shape.sets);
        y0 += 200.0;
    }
    for (name, sets) in brian.output_sets() {
        let how = if sets.iter().all(|(_, s)| matches!(s, FuzzySet::Sng { .. })) {
            "singletons"
        } else {
            "barycenter"
        };
        panel(&mut body, y0, &format!("output {name} ({how})"), sets);
        y0 += 200.0;
    }
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="860" height="{}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/>{body}</svg>"#,
        y0 + 10.0
    );
    std::fs::write(out, svg).with_context(|| format!("cannot write {}", out.display()))?;
    outln!("wrote {}", out.display());
    Ok(())
}
