//! One module per subcommand.

pub mod bias;
pub mod demo;
pub mod rate;
pub mod simulate;
