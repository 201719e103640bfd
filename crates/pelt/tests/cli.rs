//! The `pelt` command's tests in one binary
//! (one link for all of them); each module is one file of tests beside this one.

#[path = "../../pelt-render/tests/common/mod.rs"]
mod common;

#[path = "cli_bench.rs"]
mod cli_bench;
#[path = "cli_export.rs"]
mod cli_export;
#[path = "cli_fidelity.rs"]
mod cli_fidelity;
#[path = "cli_herd.rs"]
mod cli_herd;
#[path = "cli_render.rs"]
mod cli_render;
#[path = "cli_usd.rs"]
mod cli_usd;
#[path = "cli_view.rs"]
mod cli_view;
#[path = "stats_cli.rs"]
mod stats_cli;
