//! `cargo bench -p sinew-statics`: the closed-form tension interval of one joint
//! (target ≤ 200 ns on the 2-core CI machine).
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix3x2, Vector2};
use sinew_statics::{TensionLimits, tension_interval};

fn bench_interval(c: &mut Criterion) {
    // E2's joint (q = [π/7, −π/9]) with holes at 25 mm, 120° apart: a realistic block.
    let rho = 0.025;
    let jacobian = Matrix3x2::from_fn(|k, col| {
        let theta = k as f64 * std::f64::consts::TAU / 3.0 + 0.3;
        if col == 0 { rho * theta.sin() } else { -rho * theta.cos() * 0.93 }
    });
    let tau = Vector2::new(-1.0, 0.5);
    let limits = TensionLimits { f_min: 20.0, f_max: 600.0 };
    tension_interval(0, &jacobian, &tau, limits).unwrap();
    c.bench_function("tension_interval (one joint)", |b| {
        b.iter(|| tension_interval(0, black_box(&jacobian), black_box(&tau), limits))
    });
}

criterion_group!(benches, bench_interval);
criterion_main!(benches);
