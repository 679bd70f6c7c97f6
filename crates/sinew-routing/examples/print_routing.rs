//! Print the expanded routing of a robot as JSON: every cable with its joint, stiffness, tension
//! limits and holes (link + point in the link frame), base first.
//!
//! ```sh
//! cargo run -p sinew-routing --example print_routing -- robots/cdhrm5                      # cables.toml
//! cargo run -p sinew-routing --example print_routing -- robots/cdhrm5 cables-routed.toml
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(robot_dir) = args.next().map(PathBuf::from) else {
        eprintln!("usage: print_routing <robot folder> [routing file, default cables.toml]");
        return ExitCode::FAILURE;
    };
    let file = args.next().unwrap_or_else(|| sinew_routing::ROUTING_FILE.to_owned());
    let result = sinew_robot::load(&robot_dir)
        .map_err(sinew_routing::RoutingError::from)
        .and_then(|robot| sinew_routing::load(robot_dir.join(&file), &robot))
        .and_then(|routing| routing.to_json());
    match result {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
