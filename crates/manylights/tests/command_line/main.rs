//! The `manylights` program run as a user runs it, one module per subject, in one test binary:
//! arguments, renders and their tables, outputs, the first hour, the benchmark, the viewer
//! under a virtual X server. Run one subject with `cargo test -p manylights --test command_line cli::`.

mod arguments;
mod bench;
mod cli;
mod common;
mod environment;
mod farm;
mod first_hour;
mod import_circles;
mod outputs;
mod viewer;
