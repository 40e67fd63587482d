//! `mrt plan path`: one SPIKE plan (`mrt_plan::spike`, MRT manual ch. 9) on the soccer field
//! or a map file, printed as text or JSON, and drawn as SVG on request (docs/planning.md).

use anyhow::{bail, Context as _, Result};
use mrt_core::Point2;
use mrt_plan::spike::draw::Sheet;
use mrt_plan::spike::{Cell, CellState, Plan, PlanMap, Shape, Spike, SpikeParams};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// `mrt plan path`.
#[derive(clap::Args)]
pub struct PathArgs {
    /// The start, `X,Y` in metres (field frame: origin at the centre spot, x towards the east
    /// goal).
    #[arg(long, allow_hyphen_values = true)]
    pub from: String,
    /// The goal, `X,Y` in metres.
    #[arg(long, allow_hyphen_values = true)]
    pub to: String,
    /// Moving objects for this plan, discs `x,y,r;x,y,r` in metres (robots, people).
    #[arg(long, allow_hyphen_values = true)]
    pub obstacles: Option<String>,
    /// A map file (TOML, docs/planning.md). Without it: the soccer field of `--field`.
    #[arg(long, conflicts_with = "field")]
    pub map: Option<PathBuf>,
    /// The soccer field's size between its lines, `LENGTHxWIDTH` in metres (with a 1 m
    /// border and the goals' boxes, as the simulator builds it).
    #[arg(long, default_value = "18x12")]
    pub field: String,
    /// The robot's radius, m.
    #[arg(long, default_value_t = 0.25)]
    pub robot_radius: f64,
    /// How far the robot keeps from obstacles besides its radius, m.
    #[arg(long, default_value_t = 0.1)]
    pub safety: f64,
    /// The smallest cell, m (the plan's accuracy).
    #[arg(long, default_value_t = 0.01)]
    pub accuracy: f64,
    /// The trajectory's poses at most this far apart, m.
    #[arg(long, default_value_t = 0.25)]
    pub resolution: f64,
    /// Print one JSON object: `{"length_m", "waypoints", "time_us", "poses", ...}`.
    #[arg(long)]
    pub json: bool,
    /// Draw the map, the cells the plan made and the path to this SVG file.
    #[arg(long)]
    pub svg: Option<PathBuf>,
}

/// Parses `X,Y` (or `X,Y,R` when `n` is 3): `n` finite numbers.
fn numbers(text: &str, n: usize, what: &str) -> Result<Vec<f64>> {
    let values: Vec<f64> =
        text.split(',').map(|v| v.trim().parse::<f64>()).collect::<Result<_, _>>().with_context(
            || format!("{what} `{text}`: expected {n} numbers separated by commas"),
        )?;
    if values.len() != n || values.iter().any(|v| !v.is_finite()) {
        bail!("{what} `{text}`: expected {n} finite numbers separated by commas");
    }
    Ok(values)
}

fn point(text: &str, what: &str) -> Result<Point2> {
    let v = numbers(text, 2, what)?;
    Ok(Point2::new(v[0], v[1]))
}

/// The discs of `--obstacles`.
fn obstacles(text: &str) -> Result<Vec<Shape>> {
    text.split(';')
        .filter(|d| !d.trim().is_empty())
        .map(|d| {
            let v = numbers(d, 3, "obstacle")?;
            if v[2] < 0.0 {
                bail!("obstacle `{d}`: the radius must not be negative");
            }
            Ok(Shape::Disc { centre: Point2::new(v[0], v[1]), radius: v[2] })
        })
        .collect()
}

/// The map of `--map` or `--field`.
fn map(args: &PathArgs) -> Result<PlanMap> {
    if let Some(file) = &args.map {
        return Ok(PlanMap::from_file(file)?);
    }
    let sizes: Vec<&str> = args.field.split(['x', 'X']).collect();
    let parsed: Vec<f64> = sizes.iter().filter_map(|s| s.trim().parse().ok()).collect();
    match parsed[..] {
        [length, width] if sizes.len() == 2 => Ok(PlanMap::soccer_field(length, width)
            .with_context(|| format!("--field {}", args.field))?),
        _ => bail!("--field `{}`: expected LENGTHxWIDTH in metres, e.g. 18x12", args.field),
    }
}

/// `mrt plan path`.
pub fn path(args: &PathArgs) -> Result<()> {
    let (from, to) = (point(&args.from, "--from")?, point(&args.to, "--to")?);
    let moving = args.obstacles.as_deref().map(obstacles).transpose()?.unwrap_or_default();
    let params = SpikeParams {
        robot_radius: args.robot_radius,
        safety: args.safety,
        accuracy: args.accuracy,
        resolution: args.resolution,
    };
    let spike = Spike::new(map(args)?, params).context("SPIKE's options")?;
    let started = Instant::now();
    let (plan, cells) = spike.plan_drawn(from, to, &moving).context("SPIKE")?;
    let time_us = started.elapsed().as_secs_f64() * 1e6;
    if let Some(out) = &args.svg {
        std::fs::write(out, svg(&spike, &moving, &plan, &cells))
            .with_context(|| format!("cannot write {}", out.display()))?;
    }
    if args.json {
        let pair = |p: &Point2| serde_json::json!([p.x, p.y]);
        let json = serde_json::json!({
            "length_m": plan.length,
            "waypoints": plan.waypoints.iter().map(pair).collect::<Vec<_>>(),
            "time_us": time_us,
            "poses": plan.poses.iter().map(|q| serde_json::json!([q.x, q.y, q.theta])).collect::<Vec<_>>(),
            "cells": plan.cells,
            "expanded": plan.expanded,
            "start_moved": plan.snapped.0,
            "goal_moved": plan.snapped.1,
        });
        outln!("{json}");
    } else {
        let corners: Vec<String> =
            plan.waypoints.iter().map(|p| format!("({:.3}, {:.3})", p.x, p.y)).collect();
        outln!(
            "path {:.3} m, {} corners, {} poses, {:.0} µs ({} cells made, {} expanded)",
            plan.length,
            plan.waypoints.len(),
            plan.poses.len(),
            time_us,
            plan.cells,
            plan.expanded
        );
        outln!("{}", corners.join(" -> "));
        if plan.snapped.0 {
            outln!("the start is nearer an obstacle than the clearance: the path steps out first");
        }
        if plan.snapped.1 {
            outln!("the goal is nearer an obstacle than the clearance: the path ends next to it");
        }
    }
    Ok(())
}

/// The map, the cells, the obstacles and the path as SVG (north up, 40 px a metre).
fn svg(spike: &Spike, moving: &[Shape], plan: &Plan, cells: &[Cell]) -> String {
    let map = spike.map();
    let scale = 40.0;
    let (w, h) = ((map.max.x - map.min.x) * scale, (map.max.y - map.min.y) * scale);
    // A band above the map for the caption; the map below it, clipped to the area.
    let band = 44.0;
    let sheet = Sheet::of(map, scale);
    let (x, y) = (|v: f64| sheet.x(v), |v: f64| sheet.y(v));
    let mut out = String::new();
    let _ = writeln!(
        out,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{:.0}" viewBox="0 0 {w:.1} {:.1}">"##,
        h + band,
        h + band
    );
    let _ = writeln!(out, r##"<rect width="{w:.1}" height="{:.1}" fill="#ffffff"/>"##, h + band);
    let _ = writeln!(
        out,
        r##"<text x="8" y="18" font-family="sans-serif" font-size="14">SPIKE: {:.2} m, {} corners, {} cells</text>"##,
        plan.length,
        plan.waypoints.len(),
        cells.len()
    );
    let _ = writeln!(
        out,
        r##"<text x="8" y="36" font-family="sans-serif" font-size="11">green: free · grey: blocked · yellow: not split · red: moving · blue: door</text>"##
    );
    let _ = writeln!(
        out,
        r##"<defs><clipPath id="area"><rect width="{w:.1}" height="{h:.1}"/></clipPath></defs><g transform="translate(0 {band})" clip-path="url(#area)">"##
    );
    let _ = writeln!(out, r##"<rect width="{w:.1}" height="{h:.1}" fill="#f4f4f0"/>"##);
    for c in cells {
        let fill = match c.state {
            CellState::Free => "#d9f0d3",
            CellState::Blocked => "#bdbdbd",
            CellState::Mixed => "#fde0a0",
        };
        let _ = writeln!(
            out,
            r##"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="{fill}" stroke="#7f9f7f" stroke-width="0.3"/>"##,
            x(c.x),
            y(c.y + c.size),
            c.size * scale,
            c.size * scale
        );
    }
    sheet.map(&mut out, map);
    for s in moving {
        sheet.shape(&mut out, s, "#c0392b");
    }
    let path: Vec<String> =
        plan.waypoints.iter().map(|p| format!("{:.2},{:.2}", x(p.x), y(p.y))).collect();
    let _ = writeln!(
        out,
        r##"<polyline points="{}" fill="none" stroke="#1f4e9c" stroke-width="2.5" stroke-linejoin="round"/>"##,
        path.join(" ")
    );
    for (p, colour) in [(plan.waypoints.first(), "#27ae60"), (plan.waypoints.last(), "#8e44ad")] {
        if let Some(p) = p {
            let _ = writeln!(
                out,
                r##"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" fill="none" stroke="{colour}" stroke-width="2"/>"##,
                x(p.x),
                y(p.y),
                spike.params().robot_radius * scale
            );
        }
    }
    out.push_str("</g>\n");
    out.push_str("</svg>\n");
    out
}
