//! Heat maps of calculation grids: one coloured cell per grid point with its value printed
//! in it (as DIALux and Relux draw them), a legend bar, axes in m (ft) and a title with the
//! grid statistics Emin, Eavg, Emax, U₀ = Emin/Eavg and Emin/Emax.
//!
//! Drawing convention: the grid is seen from the side its normal points to, with row 0 at the
//! **bottom** and column 0 at the **left** (the origin of the grid rectangle bottom-left, like
//! a plan); the x axis runs along the first edge (`size_m.0`, columns), the y axis along the
//! second (`size_m.1`, rows).

use std::path::Path;

use image::{Rgb, RgbImage};

use super::falsecolour::{describe_scale, ColourScale, FalsecolourSettings, Legend};
use super::units::{format_sig, UnitSystem};
use crate::limits::{check_memory, printable};
use crate::output::draw::{self, BLACK, DARK_GREY, WHITE};
use crate::output::write_rgb_png;
use crate::output::OutputError;
use crate::photometry::Quantity;
use crate::world::measure::{MAX_GRID_EDGE_POINTS, MAX_GRID_NAME_CHARS, MAX_GRID_POINTS};

/// The values of one calculation grid, as the report JSON holds them.
#[derive(Clone, Debug, PartialEq)]
pub struct GridValues {
    /// The grid's name (scene file), used in the title.
    pub name: String,
    /// Points along the first edge (columns).
    pub nx: usize,
    /// Points along the second edge (rows).
    pub ny: usize,
    /// Illuminance at each point, lx; row-major, row 0 first (`values[j * nx + i]`).
    pub values: Vec<f64>,
    /// Standard error of each value, lx (same layout), or empty if unknown.
    pub stderr: Vec<f64>,
    /// Extent of the grid along its two edges, metres (for the axis labels).
    pub size_m: (f64, f64),
}

pub use crate::meter::GridStats;

impl GridStats {
    /// The same statistics converted from SI (lx) to `units` (ratios unchanged).
    pub fn in_units(&self, units: UnitSystem) -> GridStats {
        let c = |v: f64| units.from_si(Quantity::Illuminance, v);
        GridStats {
            min: c(self.min),
            avg: c(self.avg),
            max: c(self.max),
            max_stderr: self.max_stderr.map(c),
            ..*self
        }
    }
}

/// What a heat map shows, returned by [`write_grid_heatmap`].
#[derive(Clone, Debug, PartialEq)]
pub struct HeatmapInfo {
    /// Statistics in lx.
    pub stats_si: GridStats,
    /// Statistics in the display units (what the title prints).
    pub stats: GridStats,
    /// Unit symbol (`lx` or `fc`).
    pub unit: String,
    /// The title lines as printed.
    pub title_lines: Vec<String>,
    /// The colour scale (legend ticks in display units).
    pub scale: ColourScale,
    /// Side of one cell, pixels.
    pub cell_px: u32,
    /// Top-left corner of the grid (the cell of column 0, row ny − 1) in the PNG.
    pub grid_origin: (u32, u32),
    /// Size of the PNG, pixels.
    pub image_size: (u32, u32),
}

impl HeatmapInfo {
    /// Centre of the cell of point (`i`, `j`) (column, row) in PNG pixels.
    pub fn cell_centre(&self, i: usize, j: usize, ny: usize) -> (u32, u32) {
        let c = self.cell_px;
        (
            self.grid_origin.0 + i as u32 * c + c / 2,
            self.grid_origin.1 + (ny - 1 - j) as u32 * c + c / 2,
        )
    }
}

const PAD: u32 = 16;
const TITLE_PX: f32 = 20.0;
const LABEL_PX: f32 = 14.0;

/// Side of the square the grid's cells are drawn in, at most, pixels.
const MAX_GRID_PX: u32 = MAX_GRID_EDGE_POINTS;

/// Largest heat map image, pixels: the cells' square with room for the title, axes and
/// legend. It bounds the memory of any heat map (3 bytes a pixel, about 80 MB).
pub const MAX_HEATMAP_PIXELS: u64 = (MAX_GRID_PX as u64 + 1600) * (MAX_GRID_PX as u64 + 600);

/// Side of one cell in pixels: 28 to 96, so the value fits in it, unless the grid would then
/// be wider or taller than [`MAX_GRID_PX`]; then as large as fits (at least 1).
fn cell_px(nx: usize, ny: usize) -> u32 {
    let (nx, ny) = (nx.max(1) as u32, ny.max(1) as u32);
    let readable = (840 / nx).min(640 / ny).clamp(28, 96);
    readable.min(MAX_GRID_PX / nx.max(ny)).max(1)
}

/// Refuses a grid whose heat map cannot be drawn: more than [`MAX_GRID_EDGE_POINTS`] points
/// along an edge or [`MAX_GRID_POINTS`] in all, or a heat map that does not fit in the memory
/// available. Cheap: the job calls it for every grid of the scene before rendering.
pub fn check_heatmap(name: &str, nx: usize, ny: usize) -> Result<(), String> {
    let shown = printable(name, 40);
    let n = nx.saturating_mul(ny);
    if nx == 0 || ny == 0 || n as u64 > MAX_GRID_POINTS {
        return Err(format!(
            "grid {shown:?} has {nx}×{ny} points (need at least 1×1, at most {MAX_GRID_POINTS})"
        ));
    }
    if nx.max(ny) > MAX_GRID_EDGE_POINTS as usize {
        return Err(format!(
            "grid {shown:?} has {nx}×{ny} points: its heat map draws at most {MAX_GRID_EDGE_POINTS} points along an edge"
        ));
    }
    // The image, and per point its value in display units and the range's sorted copies.
    check_memory(
        MAX_HEATMAP_PIXELS * 3 + n as u64 * 24,
        &format!("the heat map of grid {shown:?}"),
    )
}

/// [`check_heatmap`] for every grid of a scene, before it is rendered.
pub fn check_heatmaps(grids: &[crate::world::measure::Grid]) -> Result<(), String> {
    grids
        .iter()
        .try_for_each(|g| check_heatmap(&g.name, g.nx as usize, g.ny as usize))
}

fn validate(grid: &GridValues) -> Result<(), String> {
    check_heatmap(&grid.name, grid.nx, grid.ny)?;
    let n = grid.nx * grid.ny;
    if grid.values.len() != n {
        return Err(format!(
            "grid '{}' has {} values, expected {}×{} = {n}",
            grid.name,
            grid.values.len(),
            grid.nx,
            grid.ny
        ));
    }
    if !grid.stderr.is_empty() && grid.stderr.len() != n {
        return Err(format!(
            "grid '{}' has {} standard errors, expected {n} (or none)",
            grid.name,
            grid.stderr.len()
        ));
    }
    if let Some(i) = grid
        .values
        .iter()
        .chain(&grid.stderr)
        .position(|v| !v.is_finite())
    {
        return Err(format!(
            "grid '{}' has a non-finite value at index {}",
            grid.name,
            i % n
        ));
    }
    let (a, b) = grid.size_m;
    if !(a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0) {
        return Err(format!(
            "grid '{}' has an invalid size {a} × {b} m",
            grid.name
        ));
    }
    Ok(())
}

/// A grid quantity other than illuminance for [`render_metric_heatmap`]: its name for the
/// title (e.g. "daylight autonomy DA300") and its unit symbol (e.g. "%", "h"); the values are
/// drawn as given.
#[derive(Clone, Debug, PartialEq)]
pub struct GridMetric {
    pub name: String,
    pub unit: String,
}

/// Renders the heat map in memory (see [`write_grid_heatmap`]).
pub fn render_grid_heatmap(
    grid: &GridValues,
    settings: &FalsecolourSettings,
) -> Result<(RgbImage, HeatmapInfo), String> {
    render_heatmap(grid, None, settings)
}

/// The heat map of a metric's values on a grid (daylight autonomy in %, hours of sun, …):
/// as [`render_grid_heatmap`], with the metric's name and unit, and its minimum, mean and
/// maximum in the title.
pub fn render_metric_heatmap(
    grid: &GridValues,
    metric: &GridMetric,
    settings: &FalsecolourSettings,
) -> Result<(RgbImage, HeatmapInfo), String> {
    render_heatmap(grid, Some(metric), settings)
}

fn render_heatmap(
    grid: &GridValues,
    metric: Option<&GridMetric>,
    settings: &FalsecolourSettings,
) -> Result<(RgbImage, HeatmapInfo), String> {
    validate(grid)?;
    let units = settings.units;
    let q = Quantity::Illuminance;
    let unit = match metric {
        Some(m) => m.unit.as_str(),
        None => units.symbol(q),
    };
    let shown: Vec<f64> = match metric {
        Some(_) => grid.values.clone(),
        None => grid.values.iter().map(|&v| units.from_si(q, v)).collect(),
    };
    let settings = FalsecolourSettings {
        quantity: q,
        ..settings.clone()
    };
    let cs = ColourScale::resolve(&settings, &shown)?;
    let stats_si = GridStats::of(&grid.values, &grid.stderr).expect("grid is not empty");
    let stats = match metric {
        Some(_) => stats_si,
        None => stats_si.in_units(units),
    };

    let title_lines = title_lines(grid, metric, &stats, unit, units);
    let subtitle = describe_scale(&cs, unit);
    let (layout, legend) = Layout::new(grid, units, &title_lines, &subtitle, &cs, unit, &shown)?;
    let mut img = RgbImage::from_pixel(layout.width, layout.height, WHITE);
    draw_title(&mut img, &title_lines, &subtitle);
    draw_cells(&mut img, &layout, grid, &shown, &cs);
    draw_axes(&mut img, &layout, grid, units);
    legend.draw(
        &mut img,
        (layout.gx + layout.gw + 24) as i32,
        layout.gy as i32,
    );

    let info = HeatmapInfo {
        stats_si,
        stats,
        unit: unit.to_string(),
        title_lines,
        scale: cs,
        cell_px: layout.cell,
        grid_origin: (layout.gx, layout.gy),
        image_size: (layout.width, layout.height),
    };
    Ok((img, info))
}

/// The title: the grid's name and quantity, its statistics, and its size (with the largest
/// standard error if known).
fn title_lines(
    grid: &GridValues,
    metric: Option<&GridMetric>,
    stats: &GridStats,
    unit: &str,
    units: UnitSystem,
) -> Vec<String> {
    let (nx, ny) = (grid.nx, grid.ny);
    let ratio = |r: Option<f64>| r.map_or("–".to_string(), |r| format!("{r:.2}"));
    let name = printable(&grid.name, MAX_GRID_NAME_CHARS);
    vec![
        match metric {
            Some(m) => format!("{name} — {} ({unit})", m.name),
            None => format!("{name} — illuminance ({unit})"),
        },
        match metric {
            Some(_) => format!(
                "min {}   mean {}   max {} {unit}",
                format_sig(stats.min, 4),
                format_sig(stats.avg, 4),
                format_sig(stats.max, 4),
            ),
            None => format!(
                "Emin {}   Eavg {}   Emax {} {unit}   U₀ = Emin/Eavg = {}   Emin/Emax = {}",
                format_sig(stats.min, 4),
                format_sig(stats.avg, 4),
                format_sig(stats.max, 4),
                ratio(stats.u0),
                ratio(stats.min_over_max),
            ),
        },
        {
            let len = units.length_symbol();
            let mut s = format!(
                "{nx} × {ny} points, {} × {} {len}",
                format_sig(units.length_from_m(grid.size_m.0), 4),
                format_sig(units.length_from_m(grid.size_m.1), 4)
            );
            if let Some(e) = stats.max_stderr {
                s += &format!("; largest standard error {} {unit}", format_sig(e, 3));
            }
            s
        },
    ]
}

/// Where the parts of a heat map go, pixels: the cells' rectangle (top-left `gx`, `gy`, size
/// `gw` × `gh`, cells of side `cell`) and the whole image.
struct Layout {
    cell: u32,
    gx: u32,
    gy: u32,
    gw: u32,
    gh: u32,
    width: u32,
    height: u32,
}

impl Layout {
    /// Lays the heat map out around its title, cells and legend (returned with it), and
    /// refuses an image past [`MAX_HEATMAP_PIXELS`] or the memory available.
    fn new<'a>(
        grid: &GridValues,
        units: UnitSystem,
        title_lines: &[String],
        subtitle: &str,
        cs: &'a ColourScale,
        unit: &'a str,
        shown: &[f64],
    ) -> Result<(Layout, Legend<'a>), String> {
        let cell = cell_px(grid.nx, grid.ny);
        let lh_title = draw::line_height(TITLE_PX);
        let lh = draw::line_height(LABEL_PX);
        let header_h = PAD + lh_title + 4 + (lh + 2) * 3 + 12 + lh + 6;
        let axis_label_w = [0.0, grid.size_m.1 / 2.0, grid.size_m.1]
            .iter()
            .map(|&m| draw::text_width(LABEL_PX, &format_sig(units.length_from_m(m), 3)))
            .max()
            .unwrap_or(0)
            .max(draw::text_width(LABEL_PX, "v (m)"));
        let (gw, gh) = (grid.nx as u32 * cell, grid.ny as u32 * cell);
        let gx = PAD + axis_label_w + 10;
        let gy = header_h;
        let clipped = (
            shown.iter().any(|&v| v < cs.min),
            shown.iter().any(|&v| v > cs.max),
        );
        let legend = Legend::new(cs, unit, None, clipped, gh.max(260));
        let footer_h = 8 + lh * 2 + PAD;
        let body_h = gh.max(legend.height);
        let mut width = gx + gw + 24 + legend.width + PAD;
        for (t, px) in title_lines
            .iter()
            .map(|t| (t.as_str(), LABEL_PX))
            .chain([(subtitle, LABEL_PX)])
        {
            width = width.max(2 * PAD + draw::text_width(px, t));
        }
        width = width.max(2 * PAD + draw::text_width(TITLE_PX, &title_lines[0]));
        let height = header_h + body_h + footer_h;
        if width as u64 * height as u64 > MAX_HEATMAP_PIXELS {
            return Err(format!(
                "the heat map of grid {:?} would be {width}×{height} pixels, more than the limit of {MAX_HEATMAP_PIXELS} pixels",
                printable(&grid.name, 40)
            ));
        }
        check_memory(
            width as u64 * height as u64 * 3,
            &format!("the heat map of grid {:?}", printable(&grid.name, 40)),
        )?;
        let layout = Layout {
            cell,
            gx,
            gy,
            gw,
            gh,
            width,
            height,
        };
        Ok((layout, legend))
    }
}

/// The title block: the title lines, then the colour scale's description in grey.
fn draw_title(img: &mut RgbImage, title_lines: &[String], subtitle: &str) {
    let lh_title = draw::line_height(TITLE_PX);
    let lh = draw::line_height(LABEL_PX);
    draw::draw_text(
        img,
        PAD as i32,
        PAD as i32,
        TITLE_PX,
        &title_lines[0],
        BLACK,
    );
    let mut y = PAD + lh_title + 4;
    for line in &title_lines[1..] {
        draw::draw_text(img, PAD as i32, y as i32, LABEL_PX, line, BLACK);
        y += lh + 2;
    }
    draw::draw_text(img, PAD as i32, y as i32, LABEL_PX, subtitle, DARK_GREY);
}

/// The cells, row 0 at the bottom, each with its value if it fits, and a frame around them.
fn draw_cells(
    img: &mut RgbImage,
    layout: &Layout,
    grid: &GridValues,
    shown: &[f64],
    cs: &ColourScale,
) {
    let Layout {
        cell,
        gx,
        gy,
        gw,
        gh,
        ..
    } = *layout;
    let (nx, ny) = (grid.nx, grid.ny);
    let value_px = (cell as f32 * 0.30).min(16.0);
    let separator = Rgb([255, 255, 255]);
    for j in 0..ny {
        for i in 0..nx {
            let v = shown[j * nx + i];
            let c = Rgb(cs.colour(v));
            let x0 = (gx + i as u32 * cell) as i32;
            let y0 = (gy + (ny - 1 - j) as u32 * cell) as i32;
            draw::fill_rect(img, x0, y0, cell, cell, c);
            // Small cells (large grids) would be all separator.
            if cell >= 8 {
                draw::stroke_rect(img, x0, y0, cell, cell, separator);
            }
            if value_px <= 7.0 {
                continue; // no room for the value in the cells of a large grid
            }
            let text = format_sig(v, 3);
            let mut px = value_px;
            while px > 7.0 && draw::text_width(px, &text) + 4 > cell {
                px -= 1.0;
            }
            if px > 7.0 {
                draw::draw_text_centred(
                    img,
                    x0 + cell as i32 / 2,
                    y0 + cell as i32 / 2,
                    px,
                    &text,
                    draw::contrasting_text(c),
                );
            }
        }
    }
    draw::stroke_rect(img, gx as i32 - 1, gy as i32 - 1, gw + 2, gh + 2, DARK_GREY);
}

/// The axes: ticks at 0, half and full extent of each edge, and the axis labels.
fn draw_axes(img: &mut RgbImage, layout: &Layout, grid: &GridValues, units: UnitSystem) {
    let Layout { gx, gy, gw, gh, .. } = *layout;
    let lh = draw::line_height(LABEL_PX);
    let len = units.length_symbol();
    for f in [0.0, 0.5, 1.0] {
        let tx = gx as f32 + f * gw as f32;
        let by = (gy + gh + 1) as f32;
        draw::draw_line(img, tx, by, tx, by + 4.0, BLACK);
        let label = format_sig(units.length_from_m(f as f64 * grid.size_m.0), 3);
        let w = draw::text_width(LABEL_PX, &label) as f32;
        let lx = (tx - w / 2.0).max(gx as f32 - 4.0);
        draw::draw_text(img, lx as i32, by as i32 + 5, LABEL_PX, &label, BLACK);

        let ty = (gy + gh) as f32 - f * gh as f32;
        let ax = gx as f32 - 2.0;
        draw::draw_line(img, ax - 4.0, ty, ax, ty, BLACK);
        let label = format_sig(units.length_from_m(f as f64 * grid.size_m.1), 3);
        let w = draw::text_width(LABEL_PX, &label) as i32;
        draw::draw_text(
            img,
            ax as i32 - 6 - w,
            ty as i32 - lh as i32 / 2,
            LABEL_PX,
            &label,
            BLACK,
        );
    }
    let xlabel = format!("u ({len}) along edge_u, row 0 at the bottom");
    draw::draw_text(
        img,
        gx as i32,
        (gy + gh + 6 + lh) as i32,
        LABEL_PX,
        &xlabel,
        DARK_GREY,
    );
    let ylabel = format!("v ({len}) along edge_v");
    draw::draw_text(
        img,
        PAD as i32,
        gy as i32 - lh as i32 - 4,
        LABEL_PX,
        &ylabel,
        DARK_GREY,
    );
}

/// Writes the heat map of `grid` to `path` (PNG, atomically). `settings.quantity` and
/// `settings.contours` are ignored (a grid holds illuminance; cells carry their values).
/// Errors (inconsistent grid, bad range, I/O) name `path`.
pub fn write_grid_heatmap(
    path: &Path,
    grid: &GridValues,
    settings: &FalsecolourSettings,
) -> Result<HeatmapInfo, OutputError> {
    let (img, info) =
        render_grid_heatmap(grid, settings).map_err(|e| OutputError::invalid(path, e))?;
    write_rgb_png(path, &img)?;
    Ok(info)
}
