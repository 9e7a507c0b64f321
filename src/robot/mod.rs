//! One Delta3 robot: kinematics and the box model of its links (thesis chapter 2, SPEC §2-§3).

pub mod delta3;
pub mod model;
#[cfg(feature = "std")]
pub mod motion_bound;
#[cfg(feature = "std")]
pub mod motor_table;
pub mod stopping;

pub use delta3::{ArmSolution, Delta3, MotorCosSin, Unreachable};
pub use model::{BoxKind, ModelOptions, RobotBoxes, RobotModel, ToolBox, MAX_BOXES};
pub use stopping::{StopModel, DEFAULT_TICK_MS};
