//! Counters of the rays and paths traced, for the closing summary and the reports.

/// Counters for the closing summary.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayStats {
    pub camera_rays: u64,
    pub bounce_rays: u64,
    pub shadow_rays: u64,
    /// Samples whose estimate was not finite and was dropped (should stay 0).
    pub non_finite: u64,
    /// Light paths traced for caustics (see [`super::light_path`]) and their rays (the camera
    /// connections count as shadow rays).
    pub light_paths: u64,
    pub light_rays: u64,
    /// Camera, meter and light paths cut short at a finite `max_depth` (0 without one): while
    /// it is above 0 the estimates lack the light of longer paths and are biased low.
    pub truncated_paths: u64,
}

impl RayStats {
    pub fn total_rays(&self) -> u64 {
        self.camera_rays + self.bounce_rays + self.shadow_rays + self.light_rays
    }
    pub fn merge(&mut self, o: &RayStats) {
        self.camera_rays += o.camera_rays;
        self.bounce_rays += o.bounce_rays;
        self.shadow_rays += o.shadow_rays;
        self.non_finite += o.non_finite;
        self.light_paths += o.light_paths;
        self.light_rays += o.light_rays;
        self.truncated_paths += o.truncated_paths;
    }
}
