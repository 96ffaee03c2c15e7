//! The report's interactive 3D viewer of a run (three.js, inline in each scene's page).

pub use self::base64::{base64, base64_f32, base64_u32};
pub use self::data::{viewer_data, VIEWER_BUDGET};
pub use self::section::{viewer_section, VIEWER_STYLE};

mod base64;
mod data;
mod section;
