//! A synthetic weather year for tests that run `candela annual` on a whole year.

use std::path::Path;

/// Writes a synthetic year in EPW format at a Lyon-like site (45.73° N, 4.94° E, UTC+1) to
/// `path`: a clear-sky model scaled by a day-to-day cloudiness drawn from a fixed sequence, so
/// the year has clear, intermediate and overcast days. Illuminance fields are left missing (the
/// irradiances count).
pub fn synthetic_year(path: &Path) {
    let mut out = String::from(
        "LOCATION,Lyon-Bron,ARA,FRA,candela synthetic,074800,45.73,4.94,1.0,201.0\n\
         DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\n\
         HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,synthetic\nCOMMENTS 2,synthetic\n\
         DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n",
    );
    let days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    let lat = 45.73f64.to_radians();
    let mut doy = 0;
    let mut state = 12345u64;
    for (m, &n) in days.iter().enumerate() {
        for d in 0..n {
            doy += 1;
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let k = [0.05, 0.3, 0.7, 1.0, 1.0][(state >> 33) as usize % 5];
            let decl = 23.45f64.to_radians()
                * (2.0 * std::f64::consts::PI * (284.0 + doy as f64) / 365.0).sin();
            for h in 1..=24 {
                let ha = (15.0 * (h as f64 - 0.5 - 12.3)).to_radians();
                let s = lat.sin() * decl.sin() + lat.cos() * decl.cos() * ha.cos();
                // Kept off the horizon: this sun is approximate (fixed solar noon), and the
                // weather file must be physically possible at the true one.
                let (dn, dh) = if s > 0.05 {
                    (
                        950.0 * (-0.17 / s).exp() * k,
                        30.0 + 250.0 * s * (1.0 - k) + 40.0 * s,
                    )
                } else {
                    (0.0, 0.0)
                };
                let ghi = dh + dn * s.max(0.0);
                out += &format!(
                    "2003,{},{},{h},60,A7A7E8E8*0?9?9?9?9?9?9?9A7A7A7A7A7*0*0E8E8*0*0,10.0,5.0,60,\
                     98600,1310,1367,350,{ghi:.0},{dn:.0},{dh:.0},999999,999999,999999,9999,180,\
                     3.0,5,3,20.0,77777,9,999999999,0,0.2,0,88,0.0,0.0,0.0\n",
                    m + 1,
                    d + 1
                );
            }
        }
    }
    std::fs::write(path, out).unwrap();
}
