//! Glare-source detection as evalglare (Radiance 6, version 3.06) does it: pixels brighter
//! than a threshold are glare pixels; glare pixels closer than half the search angle are
//! merged into one source; the peaks of a source (pixels at or above the peak limit) are
//! split off into sources of their own.

use super::image::{dot, GlareImage};
use std::collections::HashMap;

/// How the glare-pixel threshold is set (evalglare `-b`, `-t`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Threshold {
    /// A fixed luminance, cd/m² (evalglare's default, 2000 cd/m², or `-b` above 100).
    Fixed { luminance_cd_m2: f64 },
    /// A multiple of the reference luminance: the task zone's mean luminance if a task zone is
    /// given, else the mean luminance of the whole image (evalglare `-b` ≤ 100; 5 with `-t`).
    Multiple { factor: f64 },
}

impl Threshold {
    /// evalglare's reading of `-b value`: above 100 a luminance in cd/m², else a factor.
    pub fn from_evalglare_b(value: f64) -> Threshold {
        if value > 100.0 {
            Threshold::Fixed {
                luminance_cd_m2: value,
            }
        } else {
            Threshold::Multiple { factor: value }
        }
    }
}

/// A task zone (evalglare `-t x y angle`): the pixels within half of `angle_rad` of the
/// direction of pixel (`col`, `row`), row 0 at the top.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Task {
    pub col: usize,
    pub row: usize,
    /// Opening angle of the zone (its diameter), rad.
    pub angle_rad: f64,
}

/// Options of the detection, with evalglare's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectOptions {
    pub threshold: Threshold,
    pub task: Option<Task>,
    /// Search angle (evalglare `-r`, default 0.2 rad): glare pixels at most half of it apart
    /// belong to the same source.
    pub search_angle_rad: f64,
    /// Peak extraction (evalglare `-y`/`-Y`, default on at 50 000 cd/m²; `None` = `-x`).
    pub peak_limit_cd_m2: Option<f64>,
}

impl Default for DetectOptions {
    fn default() -> Self {
        DetectOptions {
            threshold: Threshold::Fixed {
                luminance_cd_m2: 2000.0,
            },
            task: None,
            search_angle_rad: 0.2,
            peak_limit_cd_m2: Some(50_000.0),
        }
    }
}

impl DetectOptions {
    /// evalglare's defaults with a task zone (`-t`): the threshold becomes 5 × the task
    /// zone's mean luminance, as evalglare does when `-b` is not given.
    pub fn with_task(task: Task) -> Self {
        DetectOptions {
            threshold: Threshold::Multiple { factor: 5.0 },
            task: Some(task),
            ..Default::default()
        }
    }
}

/// One glare source.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// Pixel indices (row-major) of the source.
    pub pixels: Vec<usize>,
    /// Solid angle ω_s, sr.
    pub solid_angle_sr: f64,
    /// Mean luminance L_s = Σ L ω / Σ ω, cd/m².
    pub luminance_cd_m2: f64,
    /// Direction of the source (unit vector, image frame): the direction of the pixel at the
    /// L·ω-weighted mean pixel position, truncated to whole pixels as evalglare does.
    pub direction: [f64; 3],
    /// Its contribution to the vertical illuminance, Σ L cosθ ω, lx.
    pub illuminance_lx: f64,
}

/// The result of the detection.
#[derive(Clone, Debug, PartialEq)]
pub struct Detection {
    pub sources: Vec<Source>,
    /// The glare-pixel threshold used, cd/m².
    pub threshold_cd_m2: f64,
    /// Mean luminance of the image's valid pixels, Σ L ω / Σ ω, cd/m².
    pub mean_luminance_cd_m2: f64,
    /// Mean luminance of the task zone, cd/m² (`None` without one).
    pub task_luminance_cd_m2: Option<f64>,
}

/// Union–find over pixel indices.
struct Dsu {
    parent: Vec<usize>,
}

impl Dsu {
    fn new(n: usize) -> Self {
        Dsu {
            parent: (0..n).collect(),
        }
    }
    fn find(&mut self, mut a: usize) -> usize {
        while self.parent[a] != a {
            self.parent[a] = self.parent[self.parent[a]];
            a = self.parent[a];
        }
        a
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb);
        }
    }
}

/// Group `pixels` into clusters whose members are linked by chains of pixels at most
/// `max_angle` rad apart (single linkage). Each cluster is returned sorted, clusters in the
/// order of their first pixel.
///
/// Pixels are bucketed in a grid of cubes of side `max_chord/√3` (so two pixels in one cube
/// are always linked) and only cube pairs within reach are compared, stopping at the first
/// linked pair; this keeps large sources (a window of 10⁵ pixels) fast.
pub fn cluster(dirs: &[[f64; 3]], pixels: &[usize], max_angle: f64) -> Vec<Vec<usize>> {
    if pixels.is_empty() {
        return Vec::new();
    }
    let cos_max = max_angle.cos();
    let chord = 2.0 * (0.5 * max_angle).sin();
    let side = chord / 3f64.sqrt();
    let key = |d: [f64; 3]| d.map(|v| (v / side).floor() as i64);
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (k, &p) in pixels.iter().enumerate() {
        cells.entry(key(dirs[p])).or_default().push(k);
    }
    let mut dsu = Dsu::new(pixels.len());
    for members in cells.values() {
        for &m in &members[1..] {
            dsu.union(members[0], m);
        }
    }
    let reach = 2i64; // chord = √3·side < 2·side: linked pixels are at most 2 cubes apart
    let keys: Vec<[i64; 3]> = cells.keys().copied().collect();
    for c in &keys {
        let a = &cells[c];
        for dx in -reach..=reach {
            for dy in -reach..=reach {
                for dz in -reach..=reach {
                    let o = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if o <= *c {
                        continue;
                    }
                    let Some(b) = cells.get(&o) else { continue };
                    if dsu.find(a[0]) == dsu.find(b[0]) {
                        continue;
                    }
                    'pairs: for &i in a {
                        for &j in b {
                            if dot(dirs[pixels[i]], dirs[pixels[j]]) >= cos_max {
                                dsu.union(i, j);
                                break 'pairs;
                            }
                        }
                    }
                }
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut index: HashMap<usize, usize> = HashMap::new();
    for (k, &p) in pixels.iter().enumerate() {
        let r = dsu.find(k);
        let g = *index.entry(r).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(p);
    }
    for g in &mut groups {
        g.sort_unstable();
    }
    groups.sort_by_key(|g| g[0]);
    groups
}

/// Build a source's summary from its pixels.
fn summarise(img: &GlareImage, lum: &[f64], view: [f64; 3], pixels: Vec<usize>) -> Source {
    let (mut om, mut lw, mut e, mut sx, mut sy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut mean_dir = [0.0; 3];
    for &p in &pixels {
        let w = img.solid_angle_sr[p];
        let l = lum[p];
        om += w;
        lw += l * w;
        e += l * dot(view, img.direction[p]) * w;
        // evalglare's pixel coordinates: x from the left, y from the bottom.
        let (col, yb) = (
            (p % img.width) as f64,
            (img.height - 1 - p / img.width) as f64,
        );
        sx += col * l * w;
        sy += yb * l * w;
        for (m, d) in mean_dir.iter_mut().zip(img.direction[p]) {
            *m += d * l * w;
        }
    }
    let mut direction = super::image::normalize(mean_dir).unwrap_or(img.direction[pixels[0]]);
    if lw > 0.0 {
        // A centre on a whole pixel coordinate (a source of one pixel, or one symmetric about
        // a pixel's centre) is that pixel: without the nudge, rounding of the weighted mean
        // sends it to the pixel before in some images and not in others.
        let nudge = 1e-9;
        let (col, yb) = ((sx / lw + nudge) as usize, (sy / lw + nudge) as usize);
        if col < img.width && yb < img.height {
            let q = (img.height - 1 - yb) * img.width + col;
            if img.valid(q) {
                direction = img.direction[q];
            }
        }
    }
    Source {
        pixels,
        solid_angle_sr: om,
        luminance_cd_m2: if om > 0.0 { lw / om } else { 0.0 },
        direction,
        illuminance_lx: e,
    }
}

/// Detect the glare sources of `img` with luminances `lum` (cd/m², one per pixel; the image's
/// own or a perturbed copy).
pub fn detect(img: &GlareImage, lum: &[f64], opt: &DetectOptions) -> Detection {
    let (view, _) = img.frame();
    let n = img.len();
    let (mut sang, mut lsum) = (0.0, 0.0);
    for i in (0..n).filter(|&i| img.valid(i)) {
        sang += img.solid_angle_sr[i];
        lsum += lum[i] * img.solid_angle_sr[i];
    }
    let mean = if sang > 0.0 { lsum / sang } else { 0.0 };
    let task_luminance = opt.task.map(|t| {
        let c = img.direction[t.row * img.width + t.col];
        let cos_half = (0.5 * t.angle_rad).cos();
        let (mut w, mut s) = (0.0, 0.0);
        for i in (0..n).filter(|&i| img.valid(i)) {
            if dot(c, img.direction[i]) >= cos_half {
                w += img.solid_angle_sr[i];
                s += lum[i] * img.solid_angle_sr[i];
            }
        }
        if w > 0.0 {
            s / w
        } else {
            0.0
        }
    });
    let threshold = match opt.threshold {
        Threshold::Fixed { luminance_cd_m2 } => luminance_cd_m2,
        Threshold::Multiple { factor } => factor * task_luminance.unwrap_or(mean),
    };
    let glare: Vec<usize> = (0..n)
        .filter(|&i| img.valid(i) && lum[i] > threshold)
        .collect();
    let half = 0.5 * opt.search_angle_rad;
    let mut groups = cluster(&img.direction, &glare, half);
    if let Some(limit) = opt.peak_limit_cd_m2 {
        let top = glare.iter().map(|&i| lum[i]).fold(0.0, f64::max);
        if top > limit {
            let mut split = Vec::new();
            for g in &mut groups {
                let (peaks, rest): (Vec<usize>, Vec<usize>) =
                    g.iter().copied().partition(|&i| lum[i] >= limit);
                if peaks.is_empty() {
                    continue;
                }
                *g = rest;
                split.extend(cluster(&img.direction, &peaks, half));
            }
            groups.retain(|g| !g.is_empty());
            groups.extend(split);
        }
    }
    Detection {
        sources: groups
            .into_iter()
            .map(|g| summarise(img, lum, view, g))
            .collect(),
        threshold_cd_m2: threshold,
        mean_luminance_cd_m2: mean,
        task_luminance_cd_m2: task_luminance,
    }
}
