//! One module per subcommand.

pub mod allan;
pub mod apply;
pub mod bias;
pub mod demo;
pub mod eval;
pub mod plan;
pub mod rate;
pub mod raw;
pub mod simulate;
pub mod static_eval;
