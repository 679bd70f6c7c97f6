//! The joint indicator, the sweep and the ellipsoid on cdhrm5 and on known matrices.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use approx::assert_relative_eq;
use faer::Mat;
use nalgebra::{Matrix3, Rotation3, Vector3};
use sinew_indicators::{AngleGrid, IndicatorError, JointProbe, StiffnessEllipsoid, sweep_joint};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, PatternModel, Routing, RoutingData, compute_cable_geometry};
use sinew_stiffness::{joint_block, joint_stiffness};
use sinew_testkit::cdhrm5;

fn cdhrm5() -> (Robot, Routing) {
    cdhrm5::robot_and_routing(PatternModel::Decoupled)
}

#[test]
fn the_indicator_is_affine_in_the_tension_level() {
    let (robot, routing) = cdhrm5();
    let mut probe = JointProbe::new(&robot, &routing, 0).unwrap();
    let q = [PI / 7.0, -PI / 9.0];
    let range = probe.evaluate(&robot, &routing, q, [-1.0, 0.5]).unwrap();
    // Direct evaluation at level s, independent of the probe's two ends.
    let mut full = vec![0.0; 10];
    full[0] = q[0];
    full[1] = q[1];
    let mut rdata = RobotData::new(&robot);
    let mut g = RoutingData::new(&routing);
    compute_cable_geometry(&routing, &robot, &mut rdata, &mut g, &full, Order::Hessians).unwrap();
    let mut ends = [nalgebra::Matrix2::zeros(); 2];
    for s in [0.0, 0.3, 0.7, 1.0] {
        let f = range.interval.tensions_at_level(s);
        let mut tensions = vec![0.0; 15];
        tensions[..3].copy_from_slice(f.as_slice());
        let (mut kc, mut ki) = (Mat::zeros(10, 10), Mat::zeros(10, 10));
        joint_stiffness(&routing, &g, &tensions, kc.as_mut(), ki.as_mut()).unwrap();
        let direct = joint_block((&kc + &ki).as_ref(), 0).unwrap();
        assert_relative_eq!(range.at_level(s), direct, max_relative = 1e-12);
        if s == 0.0 || s == 1.0 {
            ends[s as usize] = direct;
        }
    }
    // σ's width (eq. 20) against |K(λ_max) − K(λ_min)| from the two direct evaluations.
    let (sx, sy) = (range.sigma_x(), range.sigma_y());
    assert_relative_eq!(sx.delta, (ends[1] - ends[0])[(0, 0)].abs(), max_relative = 1e-12);
    assert_relative_eq!(sy.delta, (ends[1] - ends[0])[(1, 1)].abs(), max_relative = 1e-12);
    assert!(sx.delta > 0.1 && sy.delta > 0.1, "E2's segment widens both: {sx:?} {sy:?}");
}

#[test]
fn e2_more_tension_more_stiffness() {
    // Spec §6, E2: along the feasible segment every tension and the stiffness rise together.
    let (robot, routing) = cdhrm5();
    let mut probe = JointProbe::new(&robot, &routing, 0).unwrap();
    let range = probe.evaluate(&robot, &routing, [PI / 7.0, -PI / 9.0], [-1.0, 0.5]).unwrap();
    assert!(range.interval.null.iter().all(|&n| n > 0.0), "tensions rise together");
    assert!(range.k_at_max[(0, 0)] > range.k_at_min[(0, 0)], "K_x rises");
    assert!(range.k_at_max[(1, 1)] > range.k_at_min[(1, 1)], "K_y rises");
}

#[test]
fn sweep_cells_equal_single_evaluations_and_mark_infeasible_points() {
    let (robot, routing) = cdhrm5();
    let grid = AngleGrid { lower: -PI / 6.0, upper: PI / 6.0, points: 5 };
    let maps = sweep_joint(&robot, &routing, 0, [0.3, 0.3], grid, &|_, _| {}).unwrap();
    assert_eq!(maps.cells.len(), 25);
    let mut probe = JointProbe::new(&robot, &routing, 0).unwrap();
    for a in 0..5 {
        for b in 0..5 {
            let q = [grid.angle(a), grid.angle(b)];
            let single = probe.evaluate(&robot, &routing, q, [0.3, 0.3]).unwrap();
            let cell = maps.cell(a, b).unwrap();
            assert_eq!(cell.k_x, single.sigma_x());
            assert_eq!(cell.k_y, single.sigma_y());
        }
    }
    // A torque no cable set can hold: every cell infeasible, no error.
    let maps = sweep_joint(&robot, &routing, 0, [50.0, 0.0], grid, &|_, _| {}).unwrap();
    assert_eq!(maps.feasible(), 0);
}

#[test]
fn bad_probes_and_grids_are_errors() {
    let (robot, routing) = cdhrm5();
    assert!(matches!(
        JointProbe::new(&robot, &routing, 5),
        Err(IndicatorError::NoSuchJoint { joint: 5, joints: 5 })
    ));
    let mut probe = JointProbe::new(&robot, &routing, 0).unwrap();
    let err = probe.evaluate(&robot, &routing, [1.0, 0.0], [0.3, 0.3]).unwrap_err();
    assert!(
        matches!(err, IndicatorError::Robot(sinew_robot::RobotError::OutOfLimits { .. })),
        "{err:?}"
    );
    let grid = AngleGrid { lower: 0.1, upper: 0.1, points: 3 };
    assert!(matches!(
        sweep_joint(&robot, &routing, 0, [0.3, 0.3], grid, &|_, _| {}),
        Err(IndicatorError::GridRange { .. })
    ));
    let grid = AngleGrid { lower: -0.1, upper: 0.1, points: 1 };
    assert!(matches!(
        sweep_joint(&robot, &routing, 0, [0.3, 0.3], grid, &|_, _| {}),
        Err(IndicatorError::GridTooSmall { points: 1, min: 2 })
    ));
}

#[test]
fn a_joint_without_exactly_three_cables_is_named() {
    // One joint driven by four cables: the single-joint model (eq. 22–23) cannot take it.
    let robot = cdhrm5::chain_robot(1);
    let mut text = String::from(
        "tension_limits = [20.0, 600.0]\nfree_length = 3.0\n[material]\nyoungs_modulus = 12.5e9\ndiameter = 1e-3\n",
    );
    for (k, angle) in [0.0_f64, 1.5, 3.0, 4.5].iter().enumerate() {
        let (x, y) = (0.022 * angle.cos(), 0.022 * angle.sin());
        text += &format!(
            "[[cable]]\nname = \"c{k}\"\nholes = [{{ link = \"base_link\", point = [{x}, {y}, 0.0] }}, {{ link = \"link1\", point = [{x}, {y}, 0.0] }}]\n"
        );
    }
    let routing = Routing::from_toml_str(&text, "four.toml", &robot).unwrap();
    let err = JointProbe::new(&robot, &routing, 0).unwrap_err();
    assert!(matches!(err, IndicatorError::NotThreeCables { joint: 0, cables: 4 }), "{err:?}");
    assert!(err.to_string().starts_with("joint 1 has 4 cables of its own"), "{err}");
    let grid = AngleGrid { lower: -0.1, upper: 0.1, points: 3 };
    let err = sweep_joint(&robot, &routing, 0, [0.3, 0.3], grid, &|_, _| {}).unwrap_err();
    assert!(matches!(err, IndicatorError::NotThreeCables { joint: 0, cables: 4 }), "{err:?}");
}

#[test]
fn sweep_reports_progress_up_to_the_total() {
    use std::sync::Mutex;
    let (robot, routing) = cdhrm5();
    let grid = AngleGrid { lower: -0.2, upper: 0.2, points: 5 };
    let seen = Mutex::new(Vec::new());
    let record = |done: usize, total: usize| {
        if let Ok(mut seen) = seen.lock() {
            seen.push((done, total));
        }
    };
    sweep_joint(&robot, &routing, 0, [0.3, 0.3], grid, &record).unwrap();
    let mut seen = seen.into_inner().unwrap();
    seen.sort_unstable();
    // One call per row, counting up to 25 points.
    assert_eq!(seen, (1..=5).map(|r| (5 * r, 25)).collect::<Vec<_>>());
}

#[test]
fn lower_errors_arrive_by_one_path() {
    // An infeasible load is a statics error, never wrapped in a stiffness error.
    let (robot, routing) = cdhrm5();
    let mut probe = JointProbe::new(&robot, &routing, 0).unwrap();
    let err = probe.evaluate(&robot, &routing, [0.0, 0.0], [1e300, 0.0]).unwrap_err();
    assert!(err.is_infeasible(), "{err:?}");
    let nested = sinew_stiffness::StiffnessError::Statics(sinew_statics::StaticsError::Robot(
        sinew_robot::RobotError::NoJoints { source_name: "x".into() },
    ));
    assert!(matches!(IndicatorError::from(nested), IndicatorError::Robot(_)));
    let nested = sinew_routing::RoutingError::Robot(sinew_robot::RobotError::NoJoints {
        source_name: "x".into(),
    });
    assert!(matches!(IndicatorError::from(nested), IndicatorError::Robot(_)));
}

#[test]
fn ellipsoid_of_a_rotated_diagonal_stiffness() {
    let r = Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let k = r.matrix()
        * Matrix3::from_diagonal(&Vector3::new(400.0, 100.0, 25.0))
        * r.matrix().transpose();
    let e = StiffnessEllipsoid::new(&k).unwrap();
    assert_relative_eq!(e.eigenvalues, Vector3::new(25.0, 100.0, 400.0), max_relative = 1e-12);
    assert_relative_eq!(
        e.semi_axes().unwrap(),
        Vector3::new(0.04, 0.01, 0.0025),
        max_relative = 1e-12
    );
    assert_relative_eq!(e.condition_number().unwrap(), 16.0, max_relative = 1e-12);
    assert_relative_eq!(
        e.volume().unwrap(),
        4.0 / 3.0 * PI * 0.04 * 0.01 * 0.0025,
        max_relative = 1e-12
    );
    // The softest direction is the rotated z axis (up to sign).
    let softest = e.directions.column(0).into_owned();
    let expected = r * Vector3::z();
    assert_relative_eq!(softest.dot(&expected).abs(), 1.0, max_relative = 1e-12);
    assert_relative_eq!(e.directional_stiffness(&expected).unwrap(), 25.0, max_relative = 1e-12);
    assert_relative_eq!(
        e.directional_stiffness(&(3.0 * (r * Vector3::x()))).unwrap(),
        400.0,
        max_relative = 1e-12
    );
    assert!(matches!(
        e.directional_stiffness(&Vector3::zeros()),
        Err(sinew_stiffness::StiffnessError::InvalidDirection { .. })
    ));
}

#[test]
fn an_indefinite_k_fd_has_no_semi_axes() {
    let e =
        StiffnessEllipsoid::new(&Matrix3::from_diagonal(&Vector3::new(10.0, -1.0, 5.0))).unwrap();
    assert!(!e.is_positive_definite());
    assert_eq!(e.lambda_min(), -1.0);
    assert!(e.semi_axes().is_none() && e.volume().is_none() && e.condition_number().is_none());
    let nan = Matrix3::from_element(f64::NAN);
    assert!(matches!(
        StiffnessEllipsoid::new(&nan),
        Err(sinew_stiffness::StiffnessError::NonFinite { .. })
    ));
}
