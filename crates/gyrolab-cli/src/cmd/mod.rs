//! One module per subcommand.

pub mod allan;
pub mod bias;
pub mod demo;
pub mod eval;
pub mod rate;
pub mod simulate;
pub mod static_eval;
