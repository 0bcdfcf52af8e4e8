//! Annual, climate-based daylight: a year of hourly illuminances on a grid and the metrics
//! drawn from them (daylight autonomy, UDI, sDA, ASE, EN 17037 provision). The skies of the
//! year come from [`crate::daylight::patches`].

pub mod coefficients;
pub mod metrics;
pub mod output;
pub mod results;
pub mod room;
pub mod run;
pub mod sun;
pub mod view;
pub mod year;
