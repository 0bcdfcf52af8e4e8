"""A year of weather written and read back by ladybug-core's EPW class, for
tests/daylight_peers.rs: writes <dir>/year.epw (values in deterministic patterns) and prints
ladybug's reading of it as JSON: the location and, per field, (month, day, hour, value) with
ladybug's datetimes (an hourly-summed quantity labelled with the start of its hour, a
point-in-time one with its instant)."""

import json
import math
import os
import sys

from ladybug.epw import EPW
from ladybug.location import Location
from ladybug.sunpath import Sunpath

path = os.path.join(sys.argv[1], "year.epw")
epw = EPW.from_missing_values()
epw.location = Location("Lyon", "-", "FRA", 45.73, 5.08, 1.0, 240.0)
n = 8760
# Physically possible values: direct light only with the sun up at the middle of the hour,
# diffuse light within what the sun's height allows (candela refuses a file otherwise).
sun = Sunpath(45.73, 5.08, 1.0)
up = [max(0.0, math.sin(math.radians(sun.calculate_sun_from_hoy(k + 0.5).altitude)))
      for k in range(n)]
epw.direct_normal_radiation.values = [(k * 37 % 900) if up[k] > 0.05 else 0 for k in range(n)]
epw.diffuse_horizontal_radiation.values = [min(k * 13 % 300, int(40 + 500 * up[k]))
                                           for k in range(n)]
epw.global_horizontal_radiation.values = [
    round(d + b * u) for d, b, u in zip(epw.diffuse_horizontal_radiation.values,
                                        epw.direct_normal_radiation.values, up)]
epw.direct_normal_illuminance.values = [k * 3701 % 90000 for k in range(n)]
epw.diffuse_horizontal_illuminance.values = [k * 1301 % 30000 for k in range(n)]
epw.dew_point_temperature.values = [round(-5 + (k * 7 % 250) / 10, 1) for k in range(n)]
epw.save(path)

back = EPW(path)
loc = back.location
fields = {}
for name in ["direct_normal_radiation", "diffuse_horizontal_radiation",
             "direct_normal_illuminance", "diffuse_horizontal_illuminance",
             "dew_point_temperature"]:
    c = getattr(back, name)
    fields[name] = [[d.month, d.day, d.hour, v] for d, v in zip(c.datetimes, c.values)]
json.dump({"path": path, "latitude": loc.latitude, "longitude": loc.longitude,
           "time_zone": loc.time_zone, "elevation": loc.elevation, "fields": fields}, sys.stdout)
