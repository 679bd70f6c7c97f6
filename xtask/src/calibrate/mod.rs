//! `cargo xtask calibrate [--check]`: fit the single-joint geometry that the paper does not state
//! to the 20 numbers of its Table II (spec §7), and write it into `robots/cdhrm5`.
//!
//! # The model
//! One universal joint of the platform (eq. 1) with its three cables in the paper's decoupled
//! model, computed by the library as the report computes it ([`sinew::paper::table_2`], through
//! [`sinew::indicators::JointProbe`], the paper's single-joint model): at the five angles of
//! Table II, holding `τ = [0.3, 0.3]` N m with tensions in `[20, 600]` N, the range of `K_x` and
//! of `K_y` over the feasible tensions. The residuals are the 20 relative errors
//! `(ours − paper) / paper`; a parameter set for which a configuration's torque cannot be held
//! (an empty tension interval, lost force closure), or whose geometry the library rejects,
//! costs [`model::INFEASIBLE_RESIDUAL`] on each of the 20 entries instead: a large residual, no
//! panic.
//!
//! # The parameters
//! | parameter | bounds | why |
//! | --- | --- | --- |
//! | hole radius ρ (one for both discs) | [5, 27] mm | inside the φ60 mm link, ≥ 3 mm from the rim |
//! | θ0, the angle of cable 1 | free, reported modulo 120° | three cables 120° apart |
//! | d1, with d2 = 30 mm − d1 | 0 ≤ d1, d2 | the 30 mm gap between the discs is kept; no disc beyond the joint centre |
//! | k = E·A/l_c of joint 1's cables | [200, 50 000] N/m (fitted in log k) | positive; l_c between 0.2 m and 49 m |
//!
//! Why these and not more: the report prints refits with the gap free, with a radius per disc,
//! and with d2 < 0 allowed. The first two barely move the RMS (the data do not constrain them);
//! the third leaves the physical bounds (see robots/cdhrm5/README.md).
//!
//! # The solver
//! Levenberg–Marquardt (crate `levenberg-marquardt`) on unbounded variables `u`, each bounded
//! parameter mapped as `p = lo + (hi − lo)(1 + sin u)/2` (MINUIT's transform), the Jacobian by
//! central differences in `u`. The problem is not convex: the fit starts from a fixed grid of
//! [`fit::start_points`] and keeps the best. Deterministic; a few seconds in a debug build.
//!
//! # The files
//! [`model`]: the geometry and its residuals; [`fit`](mod@fit): the setups, the solver and the
//! tolerances; [`files`]: the robot files written and compared. This file prints the report.

mod files;
mod fit;
mod model;

use sinew::paper::{render_table_2, table_2_patterns};

use crate::DynResult;
use files::{compare_with_files, write_files};
use fit::{MAIN, Param, VARIANTS, fit, start_points, tolerances};
use model::{Geometry, ea, relative_errors, rms, table};

fn describe(g: &Geometry) -> String {
    let radius = if (g.rho_p - g.rho_d).abs() < 1e-9 {
        format!("ρ = {:.2} mm", 1e3 * g.rho_p)
    } else {
        format!("ρ = {:.2} / {:.2} mm (proximal / distal)", 1e3 * g.rho_p, 1e3 * g.rho_d)
    };
    format!(
        "{radius}, θ0 = {:.2}°, d1 = {:.2} mm, d2 = {:.2} mm, k = {:.0} N/m",
        g.theta0.to_degrees(),
        1e3 * g.d1,
        1e3 * g.d2,
        g.stiffness
    )
}

/// `cargo xtask calibrate [--check]`.
pub fn run(args: &[String]) -> DynResult<()> {
    let check = match args {
        [] => false,
        [flag] if flag == "--check" => true,
        _ => return Err("usage: cargo xtask calibrate [--check]".into()),
    };
    let dir = crate::project_root().join("robots/cdhrm5");
    let clock = std::time::Instant::now();
    let starts = start_points();
    let (best, fits) = fit(MAIN, &starts);
    // What the files get: the fit rounded (lengths to 0.01 mm, θ0 to 1e-5 rad).
    let written = best.geometry.rounded(ea());
    let rows = table(&written)?;
    let errors = relative_errors(&rows);

    println!("Calibration of robots/cdhrm5 against Table II (spec §7)\n");
    println!(
        "Model: one universal joint, decoupled cables, τ = [0.3, 0.3] N m, f ∈ [20, 600] N; \
         20 residuals = relative errors of the interval ends."
    );
    println!(
        "Free: {}. Levenberg–Marquardt from {} grid starts; best from start {} ({} evaluations).",
        MAIN.name,
        starts.len(),
        best.start + 1,
        best.evaluations
    );
    let near = fits.iter().filter(|f| f.rms <= best.rms + 1e-4).count();
    println!("{near} of {} starts reach the best RMS (within 0.01 pp).\n", fits.len());

    println!("Fitted parameters:\n");
    println!("| parameter | value | bounds | change costing +1 pp RMS (others refitted) |");
    println!("| --- | --- | --- | --- |");
    let tol = tolerances(&best);
    for (i, p) in MAIN.params().iter().enumerate() {
        let [lo, hi] = MAIN.bounds(*p);
        let g = &best.geometry;
        let (name, value, bounds, unit_tol) = match p {
            Param::Radius => (
                "hole radius ρ (both discs)",
                format!("{:.2} mm", 1e3 * g.rho_p),
                format!("[{:.0}, {:.0}] mm", 1e3 * lo, 1e3 * hi),
                tol[i].map(|t| format!("± {:.2} mm", 1e3 * t)),
            ),
            Param::Theta0 => (
                "θ0 (angle of cable 1)",
                format!("{:.2}° (mod 120°)", g.theta0.to_degrees()),
                "free".to_owned(),
                tol[i].map(|t| format!("± {:.2}°", t.to_degrees())),
            ),
            Param::D1 => (
                "d1 (d2 = 30 mm − d1)",
                format!("{:.2} mm (d2 = {:.2} mm)", 1e3 * g.d1, 1e3 * g.d2),
                format!("[{:.0}, {:.0}] mm", 1e3 * lo, 1e3 * hi),
                tol[i].map(|t| format!("± {:.2} mm", 1e3 * t)),
            ),
            Param::LogStiffness => (
                "k = E·A/l_c (joint 1)",
                format!("{:.0} N/m (l_c = {:.3} m)", g.stiffness, ea() / g.stiffness),
                format!("[{:.0}, {:.0}] N/m", lo.exp(), hi.exp()),
                tol[i].map(|t| format!("± {:.1} %", 100.0 * t)),
            ),
            _ => continue,
        };
        let constrained = unit_tol.unwrap_or_else(|| "on its bound".to_owned());
        println!("| {name} | {value} | {bounds} | {constrained} |");
    }

    println!("\nTable II with the values as written (rounded), ours beside the paper's:\n");
    print!("{}", render_table_2(&rows));
    println!("RMS relative error over the 20 entries, to 0.01 %: {:.2} %", 100.0 * rms(&errors));
    let worst = errors.iter().fold(0.0_f64, |a, e| a.max(e.abs()));
    println!("Largest relative error: {:.1} %\n", 100.0 * worst);
    println!(
        "Qualitative patterns of Table II (the report's check, `sinew::paper::table_2_patterns`):\n"
    );
    print!("{}", sinew::paper::render_claims(&table_2_patterns(&rows)));

    println!(
        "\nWhat the data constrain: refits from the best, each with one restriction lifted:\n"
    );
    println!("| setup | RMS | parameters |");
    println!("| --- | --- | --- |");
    println!(
        "| {} (written) | {:.2} % | {} |",
        MAIN.name,
        100.0 * best.rms,
        describe(&best.geometry)
    );
    for variant in VARIANTS {
        let mut variant_starts = vec![best.geometry];
        variant_starts.extend(starts.iter().step_by(3).copied());
        let (v, _) = fit(variant, &variant_starts);
        println!("| {} | {:.2} % | {} |", variant.name, 100.0 * v.rms, describe(&v.geometry));
    }

    println!("\nValues for the files (rounded): {}", describe(&written));
    println!("Fit took {:.1} s.", clock.elapsed().as_secs_f64());

    if check {
        let differences = compare_with_files(&dir, &written)?;
        if differences.is_empty() {
            println!("\nrobots/cdhrm5 holds the fitted values (within the check tolerances).");
            return Ok(());
        }
        return Err(format!(
            "robots/cdhrm5 differs from the fit:\n{}\nrun `cargo xtask calibrate` to write it",
            differences.join("\n")
        )
        .into());
    }
    write_files(&dir, &written)?;
    println!(
        "\nWrote robots/cdhrm5/cdhrm5.urdf, cables.toml, cables-routed.toml. \
         Update robots/cdhrm5/README.md if the values changed."
    );
    Ok(())
}
