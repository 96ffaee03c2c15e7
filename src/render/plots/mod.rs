//! Plots of a run's process (load against displacement, contact forces, Newton residuals,
//! breaks; a dynamic scene's energies and contact force against time), drawn with `plotters` as PNG and SVG beside the CSV of their points.

pub use self::breaks::breaks;
pub use self::chart::{Chart, Series, WrittenPlot, PLOT_SIZE};
pub use self::contact_forces::contact_forces;
pub use self::energies::{contact_force_time, energies};
pub use self::error::PlotError;
pub use self::load_displacement::load_displacement;
pub use self::obstacle_force::obstacle_force;
pub use self::place_force::{place_force, place_points};
pub use self::reaction::reaction;
pub use self::residuals::residuals;
pub use self::run_plots::{plot_run, PLOTS};

mod breaks;
mod chart;
mod contact_forces;
mod energies;
mod error;
mod load_displacement;
mod obstacle_force;
mod place_force;
mod reaction;
mod residuals;
mod run_plots;
