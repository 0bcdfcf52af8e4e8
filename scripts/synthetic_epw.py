#!/usr/bin/env python3
"""Write a deterministic synthetic weather year (EPW, 8760 hourly records) for a Lyon-like site.

    python scripts/synthetic_epw.py OUT.epw [--seed N] [--every K]

Site: latitude 45.72 N, longitude 4.93 E, time zone +1 h, elevation 200 m. Each day is clear,
intermediate or overcast, drawn from a seeded Markov chain whose clear-day share peaks in summer,
so the year has both long sunny and long overcast spells. Per hour:

- clear: the ASHRAE (2005) clear-sky direct-normal and diffuse-horizontal irradiance;
- intermediate: the clear direct normal scaled by an hourly random transmittance in [0.15, 0.85],
  the lost beam partly scattered into the diffuse;
- overcast: no beam, diffuse 20-45 % of the clear global.

Global horizontal = direct normal · sin(altitude) + diffuse. The illuminance fields (global,
direct normal, diffuse horizontal, zenith luminance) are filled from those irradiances with the
Perez et al. (1990) luminous efficacy model (ladybug.skymodel), the one gendaymtx and gendaylit
use, so a reader that takes either kind of field sees the same sky. The sun position is taken at
the middle of each record's hour: the EPW record of hour h covers (h-1):00-h:00 local standard
time. Needs ladybug-core (target/venv).

--every K keeps the daylight of every K-th day only (1 January, then every K days) and makes the
other days dark (no irradiance): the same weather on the kept days, a K times cheaper year for
tests, still 8760 records. Metrics over such a file count the dark days' occupied hours as dark.
"""

import argparse
import math
import random

from ladybug.epw import EPW
from ladybug.location import Location
from ladybug.skymodel import (
    ashrae_clear_sky,
    calc_horizontal_infrared,
    estimate_illuminance_from_irradiance,
    get_extra_radiation,
)
from ladybug.sunpath import Sunpath

LATITUDE_DEG = 45.72
LONGITUDE_DEG = 4.93  # east positive, as in EPW
TIME_ZONE_H = 1.0
ELEVATION_M = 200.0
DAYS_PER_MONTH = (31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31)


def day_types(rng):
    """One of 'clear', 'intermediate', 'overcast' per day of a 365-day year (Markov chain)."""
    types = []
    state = "overcast"
    for doy in range(365):
        # Clear-day share from ~20 % in midwinter to ~55 % in midsummer.
        season = 0.5 - 0.5 * math.cos(2.0 * math.pi * (doy - 15) / 365.0)
        p_clear = 0.20 + 0.35 * season
        p_over = 0.45 - 0.25 * season
        if rng.random() < 0.55:  # persistence: keep yesterday's weather
            types.append(state)
            continue
        u = rng.random()
        state = "clear" if u < p_clear else ("overcast" if u < p_clear + p_over else "intermediate")
        types.append(state)
    return types


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="EPW path to write")
    ap.add_argument("--seed", type=int, default=20260101)
    ap.add_argument("--every", type=int, default=1,
                    help="keep the daylight of every K-th day only, the others dark")
    args = ap.parse_args()
    if args.every < 1:
        ap.error("--every must be at least 1")
    rng = random.Random(args.seed)

    epw = EPW.from_missing_values(is_leap_year=False)
    loc = Location(
        city="Synthetic Lyon",
        state="-",
        country="FRA",
        latitude=LATITUDE_DEG,
        longitude=LONGITUDE_DEG,
        time_zone=TIME_ZONE_H,
        elevation=ELEVATION_M,
        station_id="000000",
        source="candela scripts/synthetic_epw.py seed %d" % args.seed,
    )
    epw._location = loc
    epw.comments_1 = "Synthetic weather year (seed %d): ASHRAE clear sky, Markov day types" % args.seed
    epw.comments_2 = "Illuminance fields from the Perez (1990) luminous efficacy model"
    sunpath = Sunpath(LATITUDE_DEG, LONGITUDE_DEG, TIME_ZONE_H)
    types = day_types(rng)

    n = 8760
    dni, dhi, ghi = [0.0] * n, [0.0] * n, [0.0] * n
    dry, dew, rh = [0.0] * n, [0.0] * n, [0.0] * n
    cover, ext_dn, ext_h = [0] * n, [0.0] * n, [0.0] * n
    i = 0
    doy = 0
    for month in range(1, 13):
        for day in range(1, DAYS_PER_MONTH[month - 1] + 1):
            kind = types[doy]
            e0 = get_extra_radiation(doy + 1)
            alts = [sunpath.calculate_sun(month, day, h - 0.5).altitude for h in range(1, 25)]
            clear_dn, clear_dh = ashrae_clear_sky(alts, month)
            # Daily temperature: seasonal swing plus a diurnal swing peaking at 15:00.
            t_mean = 12.5 - 9.0 * math.cos(2.0 * math.pi * (doy - 20) / 365.0)
            t_amp = {"clear": 6.0, "intermediate": 4.0, "overcast": 2.0}[kind]
            depression = {"clear": 8.0, "intermediate": 5.0, "overcast": 2.0}[kind]
            trans = 0.5  # hourly beam transmittance of an intermediate day (AR(1) walk)
            for h in range(1, 25):
                alt = alts[h - 1]
                s = math.sin(math.radians(alt))
                if alt > 0.0:
                    cdn, cdh = max(clear_dn[h - 1], 0.0), max(clear_dh[h - 1], 0.0)
                    if kind == "clear":
                        dn, dh = cdn, cdh
                    elif kind == "intermediate":
                        trans = min(0.85, max(0.15, 0.6 * trans + 0.4 * rng.uniform(0.15, 0.85)))
                        dn = cdn * trans
                        dh = cdh + 0.35 * (1.0 - trans) * cdn * s
                    else:
                        dn, dh = 0.0, rng.uniform(0.20, 0.45) * (cdn * s + cdh)
                    if doy % args.every != 0:
                        # Drawn all the same, so the kept days are those of the full year.
                        dn = dh = 0.0
                    dni[i], dhi[i] = round(dn), round(dh)
                    ghi[i] = round(dni[i] * s + dhi[i])
                    ext_dn[i] = round(e0)
                    ext_h[i] = round(e0 * s)
                t = t_mean + t_amp * math.cos(2.0 * math.pi * (h - 15) / 24.0)
                dry[i] = round(t, 1)
                dew[i] = round(t - depression - 1.5 * rng.random(), 1)
                # Magnus formula over water.
                es = lambda x: math.exp(17.62 * x / (243.12 + x))  # noqa: E731
                rh[i] = max(1, min(100, round(100.0 * es(dew[i]) / es(dry[i]))))
                cover[i] = {"clear": 1, "intermediate": 5, "overcast": 10}[kind]
                i += 1
            doy += 1

    gh_ill, dn_ill, dh_ill, z_lum = [0.0] * n, [0.0] * n, [0.0] * n, [0.0] * n
    i = 0
    for month in range(1, 13):
        for day in range(1, DAYS_PER_MONTH[month - 1] + 1):
            for h in range(1, 25):
                alt = sunpath.calculate_sun(month, day, h - 0.5).altitude
                if alt > 0.0 and ghi[i] > 0.0:
                    g, d, f, z = estimate_illuminance_from_irradiance(alt, ghi[i], dni[i], dhi[i], dew[i])
                    gh_ill[i], dn_ill[i], dh_ill[i], z_lum[i] = round(g), round(d), round(f), round(z)
                i += 1

    pressure = round(101325.0 * (1.0 - 2.25577e-5 * ELEVATION_M) ** 5.25588)
    ir = [calc_horizontal_infrared(c, t, d) for c, t, d in zip(cover, dry, dew)]
    fields = {
        6: dry,
        7: dew,
        8: rh,
        9: [pressure] * n,
        10: ext_h,
        11: ext_dn,
        12: [round(x) for x in ir],
        13: ghi,
        14: dni,
        15: dhi,
        16: gh_ill,
        17: dn_ill,
        18: dh_ill,
        19: z_lum,
        20: [180] * n,
        21: [3.0] * n,
        22: cover,
        23: cover,
    }
    for field, values in fields.items():
        epw._data[field].values = values
    epw.save(args.out)


if __name__ == "__main__":
    main()
