//! The tables `candela bench traversal` prints: throughput, BVH build and memory, and hit
//! agreement with Embree.

use super::super::rayfile::{RayFile, RayKind};
use super::super::{cell, median};
use super::{agreement, mrays, CandelaBvh, Embree, Times, Timing, TraversalArgs, CHUNK};
use anyhow::{bail, Result};
use std::path::Path;

/// The report's first line and its two throughput tables: wall clock, then CPU time.
pub(super) fn print_throughput(
    args: &TraversalArgs,
    file: &RayFile,
    source: &str,
    times: &Times,
    embrees: &[Embree],
) {
    println!(
        "Traversal: {} ({} triangles), medians of {} repetitions (candela and Embree alternating); threads take chunks of {CHUNK} rays from a shared counter.",
        source, file.mesh.indices.len(), args.reps
    );
    type Metric = fn(&Timing) -> f64;
    let tables: [(&str, Metric); 2] = [
        ("Wall clock: Mrays/s; ratio = candela time ÷ Embree time (≤ 1.3 is the goal).", |t| t.wall),
        ("CPU time (summed over the tracing threads, so not inflated by other processes): Mrays per CPU-second; ratio = candela CPU time ÷ Embree CPU time.", |t| t.cpu),
    ];
    for (title, metric) in tables {
        let mut head = "| rays | kind | count | threads | candela |".to_string();
        let mut rule = "|---|---|---:|---:|---:|".to_string();
        for e in embrees {
            head += &format!(" Embree {q} | ratio vs {q} |", q = e.quality);
            rule += "---:|---:|";
        }
        println!("\n{title}\n\n{head}\n{rule}");
        for (b, batch) in file.batches.iter().enumerate() {
            for (k, &threads) in args.threads.iter().enumerate() {
                let c = median(&mut times.candela[b][k].iter().map(metric).collect::<Vec<_>>());
                let mut row = format!(
                    "| {} | {} | {} | {threads} | {} |",
                    batch.name,
                    match batch.kind {
                        RayKind::Closest => "closest hit",
                        RayKind::Occluded => "any hit",
                    },
                    batch.rays.len(),
                    cell(mrays(batch.rays.len(), c), 2)
                );
                for e_times in &times.embree[b][k] {
                    let s = median(&mut e_times.iter().map(metric).collect::<Vec<_>>());
                    row += &format!(
                        " {} | {} |",
                        cell(mrays(batch.rays.len(), s), 2),
                        cell(c / s, 2)
                    );
                }
                println!("{row}");
            }
        }
    }
}

/// With --record both: the CPU-time table of the closest-hit batches with the full `Hit`.
pub(super) fn print_full_hit_throughput(
    args: &TraversalArgs,
    file: &RayFile,
    times: &Times,
    embrees: &[Embree],
) {
    let mut head = "| rays | threads | candela, full Hit |".to_string();
    let mut rule = "|---|---:|---:|".to_string();
    for e in embrees {
        head += &format!(" ratio vs {q} |", q = e.quality);
        rule += "---:|";
    }
    println!("\nCPU time with the full `Hit` record (`SceneGeometry::intersect`, what the renderer calls: adds the hit point, unit normals, shading normal and error bounds): Mrays per CPU-second; ratio = candela CPU time ÷ Embree CPU time (Embree as above).\n\n{head}\n{rule}");
    for (b, batch) in file.batches.iter().enumerate() {
        if batch.kind != RayKind::Closest {
            continue;
        }
        for (k, &threads) in args.threads.iter().enumerate() {
            let c = median(
                &mut times.candela_full[b][k]
                    .iter()
                    .map(|t| t.cpu)
                    .collect::<Vec<_>>(),
            );
            let mut row = format!(
                "| {} | {threads} | {} |",
                batch.name,
                cell(mrays(batch.rays.len(), c), 2)
            );
            for e_times in &times.embree[b][k] {
                let s = median(&mut e_times.iter().map(|t| t.cpu).collect::<Vec<_>>());
                row += &format!(" {} |", cell(c / s, 2));
            }
            println!("{row}");
        }
    }
}

/// The BVH table: build time and memory of candela's BVH and of each Embree's.
pub(super) fn print_bvh_table(
    args: &TraversalArgs,
    file: &RayFile,
    bvh: &CandelaBvh,
    embrees: &[Embree],
) {
    let n_tris = file.mesh.indices.len();
    println!(
        "\n| BVH | build s (median of {}) | bytes/triangle | total MB |\n|---|---:|---:|---:|",
        args.build_reps.max(1)
    );
    println!(
        "| candela (obvhs PLOC binary tree, medium build, collapsed to 8-wide float nodes, leaves ≤ 6; {} nodes, depth {}) | {:.3} | {:.1} | {:.1} |",
        bvh.geo.node_count(),
        bvh.geo.bvh_depth(),
        bvh.build_seconds,
        bvh.bytes / n_tris as f64,
        bvh.bytes / 1e6
    );
    for e in embrees {
        println!(
            "| Embree {} ({}) | {:.3} | {:.1} (BVH {:.1} + vertex/index buffers {:.1}) | {:.1} |",
            e.version,
            e.quality,
            e.build_seconds,
            e.bytes_total / n_tris as f64,
            (e.bytes_total - e.bytes_buffers) / n_tris as f64,
            e.bytes_buffers / n_tris as f64,
            e.bytes_total / 1e6
        );
    }
}

/// For each Embree process: its hits (written next to the ray file `rays`) against candela's,
/// a table per process.
pub(super) fn print_agreement(
    rays: &Path,
    file: &RayFile,
    times: &Times,
    embrees: &mut [Embree],
) -> Result<()> {
    let nb = file.batches.len();
    for e in embrees {
        let hit_path = rays.with_extension(format!("embree-{}-hits.bin", e.quality));
        let embree_hits = e.hits(&hit_path)?;
        if embree_hits.len() != nb {
            bail!(
                "embree_trace wrote {} batches of hits for {nb} batches of rays",
                embree_hits.len()
            );
        }
        println!(
            "\nHit agreement, candela vs Embree {} (same t: within 10⁻⁴·max(t, 1)):\n\n| rays | hit/miss agree | candela only | Embree only | both hit, t differs | max rel. Δt |\n|---|---:|---:|---:|---:|---:|",
            e.quality
        );
        for (b, batch) in file.batches.iter().enumerate() {
            let g = agreement(&times.candela_hits[b], &embree_hits[b]);
            println!(
                "| {} | {:.4} % | {} | {} | {} | {:.1e} |",
                batch.name,
                100.0 * g.agree as f64 / g.rays.max(1) as f64,
                g.only_a,
                g.only_b,
                g.t_differs,
                g.max_rel_dt
            );
        }
    }
    Ok(())
}
