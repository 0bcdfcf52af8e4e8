//! Meters and calculation grids of a scene, as built from its `meters`, `grids` and `measure`
//! sections: illuminance at a point, luminance in a cone of directions, grids of illuminance
//! meters (a work plane) with their point layout and the files their results go to, and the
//! sample budget. Measuring them is the `meter` module's.

use crate::description::context::{Context, SceneError};
use crate::description::schema::{GridDesc, MeasureDesc, MeterDesc};
use glam::Vec3;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// What a meter measures, where (positions in m) and in which directions.
#[derive(Clone, Debug)]
pub enum MeterKind {
    /// Illuminance (lx) on the hemisphere around the unit `normal`, at `position` (m).
    Illuminance { position: Vec3, normal: Vec3 },
    /// Mean luminance (cd/m²) over a cone of directions around the unit `direction`, seen from
    /// `position` (m); the cone's half-angle in radians.
    Luminance {
        position: Vec3,
        direction: Vec3,
        half_angle_rad: f32,
    },
    /// CIE 117 UGR (docs/glare.md) for an eye at `position` (m) looking along the unit
    /// `direction`, `up` a unit vector across it; its Monte Carlo estimate is the vertical
    /// illuminance (lx) at the eye, from which the background luminance comes.
    Ugr {
        position: Vec3,
        direction: Vec3,
        up: Vec3,
    },
    /// Melanopic EDI (lx) and vertical illuminance at an eye at `position` (m) looking along
    /// the unit `direction`; its Monte Carlo estimate is the illuminance (lx), and
    /// [`crate::meter::measure_melanopic`] gives both.
    Melanopic { position: Vec3, direction: Vec3 },
}

/// A named meter of the scene.
#[derive(Clone, Debug)]
pub struct Meter {
    pub name: String,
    pub kind: MeterKind,
}

/// A calculation grid of illuminance meters: `nx` × `ny` cells of the parallelogram
/// `origin + s·edge_u + t·edge_v` (m), one meter at each cell's centre facing `normal`.
#[derive(Clone, Debug)]
pub struct Grid {
    pub name: String,
    /// Corner of the grid, m.
    pub origin: Vec3,
    /// Edge along the u (i) axis, m.
    pub edge_u: Vec3,
    /// Edge along the v (j) axis, m.
    pub edge_v: Vec3,
    pub nx: u32,
    pub ny: u32,
    /// Unit normal the meters face.
    pub normal: Vec3,
}

impl Grid {
    /// The meter point of cell (i, j): the cell centre.
    pub fn point(&self, i: u32, j: u32) -> Vec3 {
        self.origin
            + self.edge_u * ((i as f32 + 0.5) / self.nx as f32)
            + self.edge_v * ((j as f32 + 0.5) / self.ny as f32)
    }
}

/// Most points of one grid.
pub const MAX_GRID_POINTS: u64 = 1_000_000;

/// Most points along one edge of a grid: its heat map draws each point as a cell of at least
/// one pixel, in a square of at most [`MAX_GRID_EDGE_POINTS`] pixels a side, so the image
/// stays under about 80 MB whatever the grid.
pub const MAX_GRID_EDGE_POINTS: u32 = 4096;

/// Longest grid name, in characters: it becomes part of two file names (file systems take
/// 255 bytes) and the heat map's title.
pub const MAX_GRID_NAME_CHARS: usize = 100;

/// Sample budget of meters.
#[derive(Clone, Debug)]
pub struct MeasureSettings {
    pub samples: u64,
    pub target_relative_error: Option<f64>,
    pub max_samples: u64,
}

impl Default for MeasureSettings {
    fn default() -> Self {
        Self {
            samples: 4096,
            target_relative_error: None,
            max_samples: 1 << 22,
        }
    }
}

/// The meters, grids and sample budget of a scene, checked: meter and grid names are unique
/// across both, and no two grids write the same file.
pub fn build_meters(
    ctx: &Context,
    meter_descs: &[MeterDesc],
    grid_descs: &[GridDesc],
    measure: &MeasureDesc,
) -> Result<(Vec<Meter>, Vec<Grid>, MeasureSettings), SceneError> {
    let mut names = HashSet::new();
    let mut meters = Vec::new();
    for (i, m) in meter_descs.iter().enumerate() {
        meters.push(Meter::build(ctx, i, m, &mut names)?);
    }
    let mut grids = Vec::new();
    let mut grid_files: HashMap<PathBuf, (usize, String)> = HashMap::new();
    for (i, g) in grid_descs.iter().enumerate() {
        grids.push(Grid::build(ctx, i, g, &mut names, &mut grid_files)?);
    }
    Ok((meters, grids, MeasureSettings::build(ctx, measure)?))
}

impl Meter {
    /// `meters[i]`, whose name must not be in `names` (it is added).
    fn build(
        ctx: &Context,
        i: usize,
        m: &MeterDesc,
        names: &mut HashSet<String>,
    ) -> Result<Meter, SceneError> {
        let field = format!("meters[{i}]");
        let (name, kind) = match m {
            MeterDesc::Illuminance {
                name,
                position,
                normal,
            } => (
                name,
                MeterKind::Illuminance {
                    position: ctx.vec3(&format!("{field}.position"), *position)?,
                    normal: ctx.unit(&format!("{field}.normal"), *normal)?,
                },
            ),
            MeterDesc::Luminance {
                name,
                position,
                direction,
                half_angle_deg,
            } => {
                let a = ctx.finite(&format!("{field}.half_angle_deg"), *half_angle_deg as f64)?;
                if !(0.0..90.0).contains(&a) {
                    return Err(ctx.err(
                        format!("{field}.half_angle_deg"),
                        format!("the acceptance half-angle must lie in [0, 90) degrees, got {a}"),
                    ));
                }
                (
                    name,
                    MeterKind::Luminance {
                        position: ctx.vec3(&format!("{field}.position"), *position)?,
                        direction: ctx.unit(&format!("{field}.direction"), *direction)?,
                        half_angle_rad: (a as f32).to_radians(),
                    },
                )
            }
            MeterDesc::Ugr {
                name,
                position,
                direction,
                up,
            } => {
                let d = ctx.unit(&format!("{field}.direction"), *direction)?;
                let u = ctx.unit(&format!("{field}.up"), up.unwrap_or([0.0, 1.0, 0.0]))?;
                let across = u - d * d.dot(u);
                if across.length() < 1e-3 {
                    return Err(ctx.err(
                        format!("{field}.up"),
                        "the up vector must not be parallel to the direction",
                    ));
                }
                (
                    name,
                    MeterKind::Ugr {
                        position: ctx.vec3(&format!("{field}.position"), *position)?,
                        direction: d,
                        up: across.normalize(),
                    },
                )
            }
            MeterDesc::Melanopic {
                name,
                position,
                direction,
            } => (
                name,
                MeterKind::Melanopic {
                    position: ctx.vec3(&format!("{field}.position"), *position)?,
                    direction: ctx.unit(&format!("{field}.direction"), *direction)?,
                },
            ),
        };
        if !names.insert(name.clone()) {
            return Err(ctx.err(
                format!("{field}.name"),
                format!("the name {name:?} is used twice"),
            ));
        }
        Ok(Meter {
            name: name.clone(),
            kind,
        })
    }
}

impl Grid {
    /// `grids[i]`, whose name must not be in `names` (it is added) and whose CSV file must not
    /// be one in `grid_files` (file → index and name of the grid writing it; it is added).
    fn build(
        ctx: &Context,
        i: usize,
        g: &GridDesc,
        names: &mut HashSet<String>,
        grid_files: &mut HashMap<PathBuf, (usize, String)>,
    ) -> Result<Grid, SceneError> {
        let field = format!("grids[{i}]");
        let shown = crate::limits::printable(&g.name, 40);
        if g.nx == 0 || g.ny == 0 || g.nx as u64 * g.ny as u64 > MAX_GRID_POINTS {
            return Err(ctx.err(
                format!("{field}.nx"),
                format!(
                    "grid {shown:?}: a grid needs 1 to {MAX_GRID_POINTS} points, got {}×{}",
                    g.nx, g.ny
                ),
            ));
        }
        for (axis, n) in [("nx", g.nx), ("ny", g.ny)] {
            if n > MAX_GRID_EDGE_POINTS {
                return Err(ctx.err(
                    format!("{field}.{axis}"),
                    format!(
                        "grid {shown:?} has {n} points along one edge, more than the limit of {MAX_GRID_EDGE_POINTS} (its heat map draws every point as a cell of at least one pixel)"
                    ),
                ));
            }
        }
        if g.name.chars().count() > MAX_GRID_NAME_CHARS {
            return Err(ctx.err(
                format!("{field}.name"),
                format!(
                    "the grid name {shown:?} has {} characters, more than the limit of {MAX_GRID_NAME_CHARS} (it names the grid's CSV and heat map files)",
                    g.name.chars().count()
                ),
            ));
        }
        let eu = ctx.vec3(&format!("{field}.edge_u"), g.edge_u)?;
        let ev = ctx.vec3(&format!("{field}.edge_v"), g.edge_v)?;
        if eu.cross(ev).length_squared() == 0.0 {
            return Err(ctx.err(
                &field,
                "the grid has zero area (edge_u and edge_v are parallel or zero)",
            ));
        }
        if !names.insert(g.name.clone()) {
            return Err(ctx.err(
                format!("{field}.name"),
                format!("the name {:?} is used twice", g.name),
            ));
        }
        // Each grid writes NAME.grid-<slug>.csv and .png: names must differ after that mapping.
        let file = grid_csv_path(Path::new("NAME"), &g.name);
        if let Some((j, other)) = grid_files.insert(file.clone(), (i, g.name.clone())) {
            return Err(ctx.err(
                format!("{field}.name"),
                format!(
                    "grids[{j}] {other:?} and grids[{i}] {:?} would both be written to {} (and .png): grid names must still differ when letters are lower-cased, every character other than an ASCII letter or digit becomes '-', leading and trailing '-' are dropped, and an empty result becomes \"grid\"",
                    g.name,
                    file.display()
                ),
            ));
        }
        Ok(Grid {
            name: g.name.clone(),
            origin: ctx.vec3(&format!("{field}.origin"), g.origin)?,
            edge_u: eu,
            edge_v: ev,
            nx: g.nx,
            ny: g.ny,
            normal: ctx.unit(&format!("{field}.normal"), g.normal)?,
        })
    }
}

impl MeasureSettings {
    /// The `measure` section.
    fn build(ctx: &Context, m: &MeasureDesc) -> Result<MeasureSettings, SceneError> {
        if m.samples == 0 {
            return Err(ctx.err("measure.samples", "meters need at least 1 sample"));
        }
        if let Some(t) = m.target_relative_error {
            if !(t.is_finite() && t > 0.0 && t < 1.0) {
                return Err(ctx.err(
                    "measure.target_relative_error",
                    format!(
                        "the target relative error must lie in (0, 1), e.g. 0.01 for 1 %, got {t}"
                    ),
                ));
            }
        }
        Ok(MeasureSettings {
            samples: m.samples,
            target_relative_error: m.target_relative_error,
            max_samples: m.max_samples.max(m.samples),
        })
    }
}

/// File-name-safe form of a grid name.
pub fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    let s = s.trim_matches('-').to_string();
    if s.is_empty() {
        "grid".into()
    } else {
        s
    }
}

/// Path of the CSV of grid `name` next to the report whose outputs share `stem`.
pub fn grid_csv_path(stem: &Path, name: &str) -> PathBuf {
    crate::output::with_suffix(stem, &format!(".grid-{}.csv", slug(name)))
}
