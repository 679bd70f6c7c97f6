//! Every crate's error says its own kind (`kind()` beside the enum) and the facade's
//! [`sinew::Error`] delegates to it; [`sinew::Error::input_at_fault`] names the input the
//! command line and Python report. Representative errors of every crate (each variant whose
//! kind a wildcard used to decide among them), by value and through the facade.

use sinew::indicators::IndicatorError;
use sinew::planner::PlanError;
use sinew::robot::RobotError;
use sinew::routing::{JointProblem, RoutingError};
use sinew::statics::{InfeasibleReason, SolverStop, StaticsError, UnsupportedRouting};
use sinew::stiffness::StiffnessError;
use sinew::{Error, ErrorKind, InputAtFault};

fn out_of_limits() -> RobotError {
    RobotError::OutOfLimits { joint: "joint1_x".into(), position: 1.0, lower: -0.5, upper: 0.5 }
}

fn infeasible() -> StaticsError {
    StaticsError::Infeasible {
        joint: 0,
        torque: [50.0, 0.0],
        limits: [20.0, 600.0],
        reason: InfeasibleReason::OutsideLimits { lambda_min: 2.0, lambda_max: 1.0 },
    }
}

fn degenerate() -> RoutingError {
    RoutingError::DegenerateSegment { cable: "j1c1".into(), segment: 0, length: 0.0, min: 1e-9 }
}

fn robot_errors() -> Vec<(RobotError, ErrorKind)> {
    vec![
        (
            RobotError::Io { path: "x.urdf".into(), source: std::io::ErrorKind::NotFound.into() },
            ErrorKind::Input,
        ),
        (
            RobotError::InvalidUrdf { source_name: "x.urdf".into(), message: "no robot".into() },
            ErrorKind::Input,
        ),
        (RobotError::NoJoints { source_name: "x.urdf".into() }, ErrorKind::Input),
        (out_of_limits(), ErrorKind::Input),
        (
            RobotError::NonFiniteAngle { joint: "joint1_x".into(), value: f64::NAN },
            ErrorKind::Input,
        ),
        (RobotError::DimensionMismatch { what: "q", expected: 10, got: 9 }, ErrorKind::Input),
        (RobotError::NoSuchBody { body: 12, bodies: 11 }, ErrorKind::Input),
        (RobotError::WorkspaceMismatch { data_dof: 4, robot_dof: 10 }, ErrorKind::Input),
    ]
}

fn routing_errors() -> Vec<(RoutingError, ErrorKind)> {
    vec![
        (degenerate(), ErrorKind::Numerical),
        (RoutingError::Serialize { message: "no".into() }, ErrorKind::Numerical),
        (
            RoutingError::Parse { file: "cables.toml".into(), message: "line 1".into() },
            ErrorKind::Input,
        ),
        (
            RoutingError::WrongJoint {
                file: "cables.toml".into(),
                cable: "c".into(),
                field: "cable[0].joint".into(),
                problem: JointProblem::AnchorOnBase,
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::ZeroLengthSegment {
                file: "cables.toml".into(),
                cable: "c".into(),
                segment: 0,
                from: "cable[0].holes[0]".into(),
                to: "cable[0].holes[1]".into(),
                length: 0.0,
                min: 1e-9,
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::InvalidTensionLimits { file: "x".into(), f_min: 5.0, f_max: 1.0 },
            ErrorKind::Input,
        ),
        (
            RoutingError::RobotMismatch {
                routing_robot: "a".into(),
                routing_dof: 10,
                robot: "b".into(),
                dof: 4,
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::WorkspaceMismatch { what: "RoutingData", expected: 15, got: 3 },
            ErrorKind::Input,
        ),
        (RoutingError::DimensionMismatch { what: "q", expected: 10, got: 9 }, ErrorKind::Input),
        (RoutingError::NoSuchCable { cable: 9, cables: 3 }, ErrorKind::Input),
        (
            RoutingError::InvalidFrictionCoefficient {
                file: "cables.toml".into(),
                cable: "c".into(),
                field: "cable[0].friction_coefficient".into(),
                value: -0.1,
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::InvalidEntryDirection {
                file: "cables.toml".into(),
                cable: "c".into(),
                field: "cable[0].entry_direction".into(),
                direction: [0.0; 3],
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::UnknownCable {
                file: "cables.toml".into(),
                field: "pattern.cable.x".into(),
                cable: "x".into(),
                joints: 5,
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::FrictionNotComputed {
                what: "capstan weights",
                call: "compute_capstan_weights",
            },
            ErrorKind::Input,
        ),
        (
            RoutingError::NotComputed { what: "Hessians", needed: sinew::routing::Order::Hessians },
            ErrorKind::Input,
        ),
        (RoutingError::Robot(out_of_limits()), ErrorKind::Input),
    ]
}

fn statics_errors() -> Vec<(StaticsError, ErrorKind)> {
    vec![
        (infeasible(), ErrorKind::Infeasible),
        (
            StaticsError::Infeasible {
                joint: 1,
                torque: [0.0; 2],
                limits: [20.0, 600.0],
                reason: InfeasibleReason::RankDeficient,
            },
            ErrorKind::Infeasible,
        ),
        (
            StaticsError::Infeasible {
                joint: 1,
                torque: [0.0; 2],
                limits: [20.0, 600.0],
                reason: InfeasibleReason::NoForceClosure { null: [1.0, -1.0, 0.0] },
            },
            ErrorKind::Infeasible,
        ),
        (
            StaticsError::NoEquilibrium(Box::new(sinew::statics::NoEquilibrium {
                joints: vec![0],
                cause: sinew::statics::NoEquilibriumCause::Unreachable {
                    direction: vec![1.0, 0.0],
                    torque: 3.0,
                },
            })),
            ErrorKind::Infeasible,
        ),
        (StaticsError::NonFiniteTorque { joint: 0, torque: [f64::NAN, 0.0] }, ErrorKind::Input),
        (StaticsError::InvalidLevel { joint: 0, level: 1.5 }, ErrorKind::Input),
        (StaticsError::UnsupportedRouting(UnsupportedRouting::OddDof { dof: 3 }), ErrorKind::Input),
        (
            StaticsError::LevelsUnavailable(UnsupportedRouting::CableLimits { cable: "c".into() }),
            ErrorKind::Input,
        ),
        (StaticsError::NoSuchJoint { joint: 7, joints: 5 }, ErrorKind::Input),
        (StaticsError::DimensionMismatch { what: "f", expected: 15, got: 3 }, ErrorKind::Input),
        (StaticsError::NonFiniteWrench { wrench: [f64::NAN; 6] }, ErrorKind::Input),
        (
            StaticsError::NotBalanced(sinew::statics::NotBalanced::Residual {
                residual: 1.0,
                t0: 2.0,
            }),
            ErrorKind::Input,
        ),
        (StaticsError::NonFiniteInput { what: "T0" }, ErrorKind::Numerical),
        (StaticsError::Numerical { what: "the SVD of J_c" }, ErrorKind::Numerical),
        (StaticsError::Solver { stop: SolverStop::MaxIterations }, ErrorKind::Numerical),
        (StaticsError::Robot(out_of_limits()), ErrorKind::Input),
        (StaticsError::Routing(degenerate()), ErrorKind::Numerical),
    ]
}

fn stiffness_errors() -> Vec<(StiffnessError, ErrorKind)> {
    vec![
        (StiffnessError::Unstable { min_eigenvalue: -1.0 }, ErrorKind::Unstable),
        (StiffnessError::RankDeficient { pivot_ratio: 1e-17 }, ErrorKind::RankDeficient),
        (StiffnessError::NonFinite { what: "K_q" }, ErrorKind::Numerical),
        (StiffnessError::Eigen, ErrorKind::Numerical),
        (StiffnessError::DimensionMismatch { what: "K_q", expected: 10, got: 9 }, ErrorKind::Input),
        // Classified numerical since before the kinds moved beside the enums (a wildcard arm
        // decided it then).
        (
            StiffnessError::WorkspaceMismatch {
                dof: 10,
                cables: 15,
                workspace_dof: 4,
                workspace_cables: 6,
            },
            ErrorKind::Numerical,
        ),
        (StiffnessError::Statics(infeasible()), ErrorKind::Infeasible),
        (StiffnessError::Robot(out_of_limits()), ErrorKind::Input),
        (StiffnessError::Routing(degenerate()), ErrorKind::Numerical),
    ]
}

fn indicator_errors() -> Vec<(IndicatorError, ErrorKind)> {
    vec![
        (IndicatorError::NoSuchJoint { joint: 9, joints: 5 }, ErrorKind::Input),
        (IndicatorError::NotThreeCables { joint: 0, cables: 2 }, ErrorKind::Input),
        (IndicatorError::NotUniversal { joint: 0, dofs: 1 }, ErrorKind::Input),
        (IndicatorError::GridTooSmall { points: 1, min: 2 }, ErrorKind::Input),
        (IndicatorError::GridRange { lower: 0.0, upper: 0.0 }, ErrorKind::Input),
        (IndicatorError::Statics(Box::new(infeasible())), ErrorKind::Infeasible),
        (
            IndicatorError::Stiffness(Box::new(StiffnessError::Unstable { min_eigenvalue: -1.0 })),
            ErrorKind::Unstable,
        ),
        (IndicatorError::Routing(degenerate()), ErrorKind::Numerical),
        (IndicatorError::Robot(out_of_limits()), ErrorKind::Input),
    ]
}

fn planner_errors() -> Vec<(PlanError, ErrorKind)> {
    vec![
        (PlanError::NonConservativeLoad { moment: [0.0, 1.0, 0.0] }, ErrorKind::Input),
        (
            PlanError::InvalidInput {
                what: "direction",
                problem: sinew::planner::InputProblem::NotUnitDirection,
            },
            ErrorKind::Input,
        ),
        (
            PlanError::NoStableTensions { margin: 1.0, best: 0.5, budget: false },
            ErrorKind::Infeasible,
        ),
        (PlanError::BudgetTooSmall { budget: 50.0, least: 80.0 }, ErrorKind::Infeasible),
        (PlanError::BudgetsInfeasible, ErrorKind::Infeasible),
        (
            PlanError::RequirementUnreachable { what: "stiffness", required: 2.0, best: 1.0 },
            ErrorKind::Infeasible,
        ),
        (PlanError::NoEndStiffness, ErrorKind::RankDeficient),
        (
            PlanError::NotConverged { iterations: 100, gap: 1e-2, tolerance: 1e-6 },
            ErrorKind::Numerical,
        ),
        (PlanError::Solver { stop: SolverStop::MaxIterations }, ErrorKind::Numerical),
        (PlanError::Numerical { what: "eigendecomposition of K_q + K_W" }, ErrorKind::Numerical),
        (PlanError::Statics(Box::new(infeasible())), ErrorKind::Infeasible),
        (
            PlanError::Stiffness(Box::new(StiffnessError::Unstable { min_eigenvalue: -1.0 })),
            ErrorKind::Unstable,
        ),
        (PlanError::Routing(Box::new(degenerate())), ErrorKind::Numerical),
    ]
}

/// Each error's kind, from its own crate and through the facade, agree with the table.
fn check<E: Into<Error> + std::fmt::Display>(
    cases: Vec<(E, ErrorKind)>,
    kind: impl Fn(&E) -> ErrorKind,
) {
    for (e, expected) in cases {
        let message = e.to_string();
        assert_eq!(kind(&e), expected, "{message}");
        let e: Error = e.into();
        assert_eq!(e.kind(), expected, "{message} (through sinew::Error)");
        assert_eq!(e.is_infeasible(), expected == ErrorKind::Infeasible, "{message}");
    }
}

#[test]
fn every_crate_says_its_own_kind() {
    check(robot_errors(), RobotError::kind);
    check(routing_errors(), RoutingError::kind);
    check(statics_errors(), StaticsError::kind);
    check(stiffness_errors(), StiffnessError::kind);
    check(indicator_errors(), IndicatorError::kind);
    check(planner_errors(), PlanError::kind);
    let other = Error::Other { message: "x.urdf: cannot read".into() };
    assert_eq!(other.kind(), ErrorKind::Input);
}

#[test]
fn nested_errors_arrive_by_one_path() {
    // However deep the nesting, the error lands in the variant of the crate that raised it.
    let deep = StiffnessError::Statics(StaticsError::Routing(RoutingError::Robot(out_of_limits())));
    assert!(matches!(Error::from(deep), Error::Robot(RobotError::OutOfLimits { .. })));
    let e = Error::from(IndicatorError::from(StiffnessError::Statics(infeasible())));
    assert!(matches!(&e, Error::Statics(s) if matches!(**s, StaticsError::Infeasible { .. })));
    let e = Error::from(IndicatorError::Robot(out_of_limits()));
    assert!(matches!(e, Error::Robot(_)));
    let e = Error::from(StiffnessError::Routing(RoutingError::NoSuchCable { cable: 1, cables: 0 }));
    assert!(matches!(e, Error::Routing(RoutingError::NoSuchCable { .. })));
    let e = Error::from(IndicatorError::from(StiffnessError::Unstable { min_eigenvalue: -1.0 }));
    assert!(matches!(&e, Error::Stiffness(s) if matches!(**s, StiffnessError::Unstable { .. })));
    assert_eq!(e.kind(), ErrorKind::Unstable);
    let e = Error::from(PlanError::from(StiffnessError::Statics(infeasible())));
    assert!(matches!(&e, Error::Statics(s) if matches!(**s, StaticsError::Infeasible { .. })));
    // Built by hand around the normalisation, the kind is still found.
    let e = Error::Stiffness(Box::new(StiffnessError::Statics(infeasible())));
    assert_eq!(e.kind(), ErrorKind::Infeasible);
    // A crate's own errors land in its own variant.
    let e = Error::from(IndicatorError::GridTooSmall { points: 1, min: 2 });
    assert!(matches!(e, Error::Indicators(IndicatorError::GridTooSmall { points: 1, min: 2 })));
    let e = Error::from(PlanError::BudgetsInfeasible);
    assert!(matches!(&e, Error::Planner(p) if matches!(**p, PlanError::BudgetsInfeasible)));
    assert_eq!(e.kind(), PlanError::BudgetsInfeasible.kind());
}

#[test]
fn the_input_at_fault_is_named() {
    let cases: Vec<(Error, Option<InputAtFault>)> = vec![
        (out_of_limits().into(), Some(InputAtFault::JointAngle { joint: "joint1_x".into() })),
        (
            RobotError::NonFiniteAngle { joint: "joint2_y".into(), value: f64::NAN }.into(),
            Some(InputAtFault::JointAngle { joint: "joint2_y".into() }),
        ),
        // Reached through other crates, the robot's error keeps its input.
        (
            StiffnessError::Robot(out_of_limits()).into(),
            Some(InputAtFault::JointAngle { joint: "joint1_x".into() }),
        ),
        (
            StaticsError::InvalidLevel { joint: 4, level: -0.5 }.into(),
            Some(InputAtFault::Levels { joint: 4 }),
        ),
        (
            StaticsError::NonFiniteWrench { wrench: [f64::NAN; 6] }.into(),
            Some(InputAtFault::Wrench),
        ),
        (
            StaticsError::NonFiniteTorque { joint: 2, torque: [f64::NAN, 0.0] }.into(),
            Some(InputAtFault::Torque { joint: 2 }),
        ),
        (
            PlanError::NonConservativeLoad { moment: [0.0, 1.0, 0.0] }.into(),
            Some(InputAtFault::Wrench),
        ),
        (
            PlanError::InvalidInput {
                what: "k_des",
                problem: sinew::planner::InputProblem::NotSymmetricPositiveDefinite,
            }
            .into(),
            Some(InputAtFault::PlannerArgument { name: "k_des" }),
        ),
        (
            IndicatorError::NoSuchJoint { joint: 8, joints: 5 }.into(),
            Some(InputAtFault::Joint { joint: 8 }),
        ),
        (
            IndicatorError::NotThreeCables { joint: 1, cables: 2 }.into(),
            Some(InputAtFault::Joint { joint: 1 }),
        ),
        (
            IndicatorError::NotUniversal { joint: 0, dofs: 1 }.into(),
            Some(InputAtFault::Joint { joint: 0 }),
        ),
        (
            IndicatorError::GridTooSmall { points: 1, min: 2 }.into(),
            Some(InputAtFault::GridPoints { points: 1 }),
        ),
        (
            IndicatorError::GridRange { lower: 0.0, upper: 0.0 }.into(),
            Some(InputAtFault::JointLimits),
        ),
        // Errors that name no single input.
        (StaticsError::NoSuchJoint { joint: 7, joints: 5 }.into(), None),
        (
            StaticsError::NotBalanced(sinew::statics::NotBalanced::Residual {
                residual: 1.0,
                t0: 2.0,
            })
            .into(),
            None,
        ),
        (StiffnessError::InvalidDirection { direction: [0.0; 3] }.into(), None),
        (infeasible().into(), None),
        (PlanError::BudgetsInfeasible.into(), None),
        (RoutingError::NoSuchCable { cable: 9, cables: 3 }.into(), None),
        (StiffnessError::Unstable { min_eigenvalue: -1.0 }.into(), None),
        (Error::Other { message: "x.urdf: cannot read".into() }, None),
    ];
    for (e, expected) in cases {
        assert_eq!(e.input_at_fault(), expected, "{e}");
    }
}

#[test]
fn messages_name_the_input_or_the_infeasible_load() {
    let name = |input: &InputAtFault| format!("<{input:?}>");
    let e: Error = StaticsError::InvalidLevel { joint: 4, level: -0.5 }.into();
    assert_eq!(e.message_naming(name), format!("<Levels {{ joint: 4 }}>: {e}"));
    let e: Error = infeasible().into();
    assert_eq!(e.message_naming(name), format!("infeasible load: {e}"));
    let e: Error = PlanError::from(infeasible()).into();
    assert_eq!(e.message_naming(name), format!("infeasible load: {e}"));
    let e: Error = PlanError::BudgetsInfeasible.into();
    assert_eq!(e.message_naming(name), format!("infeasible: {e}"));
    let e: Error = StiffnessError::Unstable { min_eigenvalue: -1.0 }.into();
    assert_eq!(e.message_naming(name), e.to_string());
}
