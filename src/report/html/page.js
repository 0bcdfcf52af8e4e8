// candela's HTML report: decodes the embedded float planes, tone-maps the image, probes pixels
// with the formulas of src/report/probe.rs and formats them as `candela probe` does
// (src/cli/probe.rs), draws false colour, the grids and the meters. No network: everything is
// in the page. See docs/report-html.md.
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("candela-data").textContent);
  const W = D.width, H = D.height, N = W * H;
  const $ = (id) => document.getElementById(id);
  const ch = {};
  const state = {
    units: "si", ev: D.auto_exposure_ev, fc: false, fcQ: "luminance", fcScale: "linear",
    palette: "turbo", min: null, max: null, px: null, pinned: false,
  };

  // ---- number formatting exactly as Rust's format! (round half to even on the exact value)
  function exactDigits(a) { // a > 0, finite: significant digits and the exponent of the first
    const s = a.toExponential(100);
    const k = s.indexOf("e");
    return { digits: s.slice(0, k).replace(".", ""), exp: parseInt(s.slice(k + 1), 10) };
  }
  function roundDigits(digits, keep) { // the first `keep` digits, rounded half to even
    if (keep < 0) return { d: "", carry: false };
    if (keep >= digits.length) return { d: digits + "0".repeat(keep - digits.length), carry: false };
    const next = digits.charCodeAt(keep) - 48;
    const rest = digits.slice(keep + 1);
    const prev = keep > 0 ? digits.charCodeAt(keep - 1) - 48 : 0;
    const up = next > 5 || (next === 5 && (/[1-9]/.test(rest) || prev % 2 === 1));
    const kept = digits.slice(0, keep).split("");
    if (!up) return { d: kept.join(""), carry: false };
    let i = kept.length - 1;
    while (i >= 0 && kept[i] === "9") { kept[i] = "0"; i--; }
    if (i < 0) return { d: "1" + kept.join(""), carry: true };
    kept[i] = String.fromCharCode(kept[i].charCodeAt(0) + 1);
    return { d: kept.join(""), carry: false };
  }
  function nonFinite(v) { return Number.isNaN(v) ? "NaN" : v > 0 ? "inf" : "-inf"; }
  // format!("{:.d}", v); plus: format!("{:+.d}", v)
  function fixed(v, d, plus) {
    if (!Number.isFinite(v)) return (plus && v > 0 ? "+" : "") + nonFinite(v);
    const neg = v < 0 || Object.is(v, -0);
    const a = Math.abs(v);
    let n = "0";
    if (a > 0) {
      const e = exactDigits(a);
      const r = roundDigits(e.digits, e.exp + d + 1);
      n = r.d.replace(/^0+/, "") || "0";
    }
    while (n.length < d + 1) n = "0" + n;
    const s = d > 0 ? n.slice(0, n.length - d) + "." + n.slice(n.length - d) : n;
    return (neg ? "-" : plus ? "+" : "") + s;
  }
  // format!("{:.de}", v)
  function expo(v, d) {
    if (!Number.isFinite(v)) return nonFinite(v);
    const a = Math.abs(v);
    if (a === 0) return (v < 0 || Object.is(v, -0) ? "-" : "") + "0" + (d > 0 ? "." + "0".repeat(d) : "") + "e0";
    const e = exactDigits(a);
    const r = roundDigits(e.digits, d + 1);
    const digits = r.carry ? r.d.slice(0, d + 1) : r.d;
    const exp = e.exp + (r.carry ? 1 : 0);
    return (v < 0 ? "-" : "") + digits[0] + (d > 0 ? "." + digits.slice(1) : "") + "e" + exp;
  }
  function trimZeros(s) { return s.includes(".") ? s.replace(/0+$/, "").replace(/\.$/, "") : s; }
  // candela::report::units::format_sig
  function sig(v, n) {
    if (!Number.isFinite(v)) return nonFinite(v);
    if (v === 0) return "0";
    const a = Math.abs(v);
    if (!(a >= 1e-3 && a < 1e6)) {
      const s = expo(v, Math.max(n - 1, 0));
      const k = s.indexOf("e");
      return trimZeros(s.slice(0, k)) + s.slice(k);
    }
    const before = Math.floor(Math.log10(a)) + 1;
    return trimZeros(fixed(v, Math.max(n - before, 0)));
  }

  // ---- decoding: base64 → inflate (DecompressionStream) → undo byte deltas → f32 planes
  function fromBase64(s) {
    if (Uint8Array.fromBase64) return Uint8Array.fromBase64(s);
    const bin = atob(s);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }
  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }
  async function decode(c) {
    const b = await inflate(fromBase64(c.data));
    for (let i = 1; i < b.length; i++) b[i] = (b[i] + b[i - 1]) & 255;
    const out = new Float32Array(N);
    const bytes = new Uint8Array(out.buffer);
    for (let i = 0; i < N; i++) {
      bytes[4 * i] = b[i]; bytes[4 * i + 1] = b[N + i];
      bytes[4 * i + 2] = b[2 * N + i]; bytes[4 * i + 3] = b[3 * N + i];
    }
    return out;
  }

  // ---- units
  const U = () => D.units[state.units];
  const lumUnit = () => U().luminance.symbol;
  const illUnit = () => U().illuminance.symbol;
  const fromSi = (q, v) => v / U()[q].si_per_unit;
  const siFromReport = (q, v) => {
    const sys = D.report && D.report.units && D.report.units.system === "imperial" ? "imperial" : "si";
    return v * D.units[sys][q].si_per_unit;
  };

  // ---- colour (src/colour/models.rs, temperature.rs, rgb.rs)
  const sdiv = (a, b) => (b === 0 ? 0 : a / b);
  function uv1960(x, y, z) {
    const u = 2 / 3 * x, v = y, w = 0.5 * (-x + 3 * y + z), s = u + v + w;
    return [sdiv(u, s), sdiv(v, s)];
  }
  let planckTable = null;
  function planckUv(t) {
    const [cx, cy, cz] = D.colour.cmfs_360_780;
    let X = 0, Y = 0, Z = 0;
    for (let i = 0; i <= 420; i++) {
      const l = (360 + i) * 1e-9;
      const l2 = l * l, l5 = l * (l2 * l2);
      const d = 1 / Math.expm1(D.colour.c2 / (l * t));
      const p = ((D.colour.c1 * (1 / l5)) / Math.PI) * d * 1e-9;
      X += p * cx[i]; Y += p * cy[i]; Z += p * cz[i];
    }
    return uv1960(X, Y, Z);
  }
  function table() { // colour-science's planckian_table(cmfs, 1000, 100000, 1.001)
    if (planckTable) return planckTable;
    const start = 1000, end = 100000, spacing = 1.001;
    const ti = [start, start + 1];
    let next = start + 1, nextSpacing = spacing;
    for (;;) {
      next *= nextSpacing;
      if (next >= end) break;
      ti.push(next);
      const d = Math.min(Math.max((next - start) / (end - start), 0), 1);
      nextSpacing = spacing * (1 - d) + (1 + (spacing - 1) / 10) * d;
    }
    ti.push(end - 1, end);
    planckTable = ti.map((t) => { const uv = planckUv(t); return [t, uv[0], uv[1]]; });
    return planckTable;
  }
  function cctOhno2013(uv) {
    const T = table();
    const dist = (r) => Math.hypot(r[1] - uv[0], r[2] - uv[1]);
    let index = 0, best = Infinity;
    for (let k = 0; k < T.length; k++) { const d = dist(T[k]); if (d < best) { best = d; index = k; } }
    if (index === 0) index = 1; else if (index === T.length - 1) index -= 1;
    const p = T[index - 1], c = T[index], n = T[index + 1];
    const [tip, uip, vip] = p, dip = dist(p);
    const ti = c[0], di = dist(c);
    const [tin, uin, vin] = n, din = dist(n);
    const l = Math.hypot(uin - uip, vin - vip);
    const x = (dip * dip - din * din + l * l) / (2 * l);
    const tT = tip + (tin - tip) * (x / l);
    const vtx = vip + (vin - vip) * (x / l);
    const dv = uv[1] - vtx, sign = dv > 0 ? 1 : dv < 0 ? -1 : 0; // numpy sign: 0 for ±0
    const duvT = Math.sqrt(dip * dip - x * x) * sign;
    const xx = (tin - ti) * (tip - tin) * (ti - tip);
    const a = (tip * (din - di) + ti * (dip - din) + tin * (di - dip)) / xx;
    const b = -(tip * tip * (din - di) + ti * ti * (dip - din) + tin * tin * (di - dip)) / xx;
    const cc = -(dip * (tin - ti) * ti * tin + di * (tip - tin) * tip * tin + din * (ti - tip) * tip * ti) / xx;
    const tP = -b / (2 * a);
    const duvP = (a * tP * tP + b * tP + cc) * sign;
    return Math.abs(duvT) >= 0.002 ? [tP, duvP] : [tT, duvT];
  }
  const M = D.colour.xyz_to_srgb;
  const toSrgb = (x, y, z) => [0, 1, 2].map((r) => M[r][0] * x + M[r][1] * y + M[r][2] * z);
  const encode = (v) => (v <= 0.0031308 ? v * 12.92 : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);

  // ---- the probe of one pixel (candela::report::probe::probe with no radius)
  function estimateText(mean, se, unit) { // src/cli/probe.rs estimate_text
    if (se !== null) {
      const t = D.probe.t95 === null ? Infinity : D.probe.t95;
      const lo = mean - t * se, hi = mean + t * se;
      return `${sig(mean, 5)} ± ${sig(t * se, 3)} ${unit}   (95 % CI ${sig(lo, 5)} … ${sig(hi, 5)}; standard error ${sig(se, 3)})`;
    }
    return `${sig(mean, 5)} ${unit}   (confidence interval unknown: no standard error channel, or fewer than 2 samples per pixel)`;
  }
  // Illuminance-like channel c (E or melanopic.EDI) with its standard error channel.
  function eLike(i, c, seC, unit) {
    const e = ch[c][i], mask = ch["mask.E"], seCh = ch[seC];
    const defined = Number.isFinite(e) && e !== D.probe.sentinel && e >= 0 && (!mask || mask[i] > 0);
    if (!defined) return "undefined: pixel sees no surface";
    const m = mask ? mask[i] : 1;
    const spp = D.probe.spp;
    const tooFew = (spp !== null && m * spp < 1.5) || (!!seCh && seCh[i] === 0 && m > 0 && m < 1);
    const se = seCh && !D.probe.too_few_samples && !tooFew ? fromSi("illuminance", seCh[i]) : null;
    let t = estimateText(fromSi("illuminance", e), se, unit);
    if (mask && m < 1) t += `; coverage ${sig(m, 3)}`;
    return t;
  }
  function probeText(px, py) {
    const i = py * W + px;
    const out = {};
    const lu = lumUnit(), eu = illUnit();
    const seY = ch["stderr.Y"];
    out.lum = estimateText(fromSi("luminance", ch.Y[i]),
      seY && !D.probe.too_few_samples ? fromSi("luminance", seY[i]) : null, lu);
    out.ill = ch.E ? eLike(i, "E", "stderr.E", eu) : "no E channel in this image (render with --illuminance)";
    if (ch["melanopic.EDL"]) {
      const se = ch["stderr.melanopic.EDL"];
      out.medl = estimateText(fromSi("luminance", ch["melanopic.EDL"][i]),
        se && !D.probe.too_few_samples ? fromSi("luminance", se[i]) : null, lu);
    }
    if (ch["melanopic.EDI"]) out.medi = eLike(i, "melanopic.EDI", "stderr.melanopic.EDI", eu);
    out.xy = out.upvp = out.cct = out.srgbLinear = out.srgbEncoded = "";
    if (!(ch.X && ch.Z)) { out.xyz = "no X/Z channels"; return out; }
    const X = ch.X[i], Y = ch.Y[i], Z = ch.Z[i];
    out.xyz = `${sig(fromSi("luminance", X), 5)} ${sig(fromSi("luminance", Y), 5)} ${sig(fromSi("luminance", Z), 5)} ${lu}`;
    const s = X + Y + Z;
    out.xy = `${fixed(sdiv(X, s), 4)} ${fixed(sdiv(Y, s), 4)}`;
    const d = X + 15 * Y + 3 * Z;
    out.upvp = `${fixed(sdiv(4 * X, d), 4)} ${fixed(sdiv(9 * Y, d), 4)}`;
    const positive = Y > 0;
    let cct = null;
    if (positive) {
      const c = cctOhno2013(uv1960(X, Y, Z));
      if (c.every(Number.isFinite)) cct = c;
    }
    if (cct) {
      out.cct = `${fixed(cct[0], 0)} K   Duv ${fixed(cct[1], 4, true)}`;
      if (Math.abs(cct[1]) > 0.05) out.cct += "  (|Duv| > 0.05: CCT is not meaningful)";
    } else {
      out.cct = "undefined (black)";
    }
    if (positive) {
      const l = toSrgb(X / Y, Y / Y, Z / Y);
      const e = l.map(encode);
      const gamut = l.some((c) => !(c >= -1e-9 && c <= 1 + 1e-9)) ? "  (outside 0…1: out of gamut or brighter than white)" : "";
      out.srgbLinear = `${l.map((c) => fixed(c, 4)).join(" ")}   (Y = 1)${gamut}`;
      const hex = e.map((c) => Math.round(Math.min(Math.max(c, 0), 1) * 255).toString(16).toUpperCase().padStart(2, "0")).join("");
      out.srgbEncoded = `${e.map((c) => fixed(c, 4)).join(" ")}   #${hex}`;
    }
    return out;
  }
  function showProbe() {
    if (state.px === null) return;
    const [x, y] = state.px;
    const t = probeText(x, y);
    $("p-pixel").textContent = `pixel (${x}, ${y})${state.pinned ? " (pinned)" : ""}`;
    $("p-lum").textContent = t.lum;
    $("p-ill").textContent = t.ill;
    $("r-medl").hidden = t.medl === undefined;
    $("r-medi").hidden = t.medi === undefined;
    $("p-medl").textContent = t.medl || "";
    $("p-medi").textContent = t.medi || "";
    $("p-xyz").textContent = t.xyz;
    $("p-xy").textContent = t.xy;
    $("p-upvp").textContent = t.upvp;
    $("p-cct").textContent = t.cct;
    $("p-srgb-linear").textContent = t.srgbLinear;
    $("p-srgb-encoded").textContent = t.srgbEncoded;
    placeMarker();
  }
  // The marker follows the layout (the legend, the window's size and the zoom change it).
  function placeMarker() {
    if (state.px === null) return;
    const [x, y] = state.px;
    const c = $("image"), m = $("marker");
    const sx = c.clientWidth / W, sy = c.clientHeight / H;
    m.hidden = false;
    m.style.left = `${c.offsetLeft + c.clientLeft + x * sx}px`;
    m.style.top = `${c.offsetTop + c.clientTop + y * sy}px`;
    m.style.width = `${Math.max(sx, 3)}px`;
    m.style.height = `${Math.max(sy, 3)}px`;
    m.classList.toggle("pinned", state.pinned);
  }

  // ---- false colour scale (src/report/falsecolour/scale.rs)
  function currentScale() {
    const q = state.fcQ, auto = (D.scales[q] && D.scales[q][state.fcScale] && D.scales[q][state.fcScale][state.units]) || null;
    let min = state.min !== null ? state.min : auto ? auto.min : 0;
    let max = state.max !== null ? state.max : auto ? auto.max : 1;
    let ticks;
    if (auto && state.min === null && state.max === null) ticks = auto.ticks;
    else if (state.fcScale === "linear") ticks = Array.from({ length: 11 }, (_, k) => min + (max - min) * k / 10);
    else {
      ticks = [min];
      for (let e = Math.floor(Math.log10(min)); e <= Math.ceil(Math.log10(max)); e++) {
        for (const m of [1, 2, 5]) { const v = m * Math.pow(10, e); if (v > min * 1.0001 && v < max / 1.0001) ticks.push(v); }
      }
      ticks.push(max);
    }
    return { min, max, ticks, log: state.fcScale === "log" };
  }
  function position(s, v) {
    let t = s.log ? (v > 0 ? Math.log(v / s.min) / Math.log(s.max / s.min) : 0) : (v - s.min) / (s.max - s.min);
    return Number.isNaN(t) ? 0 : Math.min(Math.max(t, 0), 1);
  }
  const paletteColour = (t) => D.palettes[state.palette][Math.round(t * 255)];
  function eDefined(i) {
    const e = ch.E[i], m = ch["mask.E"];
    return e !== D.probe.sentinel && e >= 0 && (!m || m[i] > 0);
  }

  // ---- drawing
  let img = null, ctx = null;
  function draw() {
    const c = $("image");
    if (!ctx) { c.width = W; c.height = H; ctx = c.getContext("2d"); img = ctx.createImageData(W, H); }
    const p = img.data;
    if (state.fc && (state.fcQ === "luminance" || ch.E)) {
      const s = currentScale(), q = state.fcQ, v = q === "luminance" ? ch.Y : ch.E;
      const k = U()[q].si_per_unit;
      for (let i = 0; i < N; i++) {
        const o = 4 * i;
        if (q === "illuminance" && !eDefined(i)) {
          const g = ((i % W) + Math.floor(i / W)) % 4 < 2 ? 150 : 200; // hatched grey
          p[o] = p[o + 1] = p[o + 2] = g;
        } else {
          const col = paletteColour(position(s, v[i] / k));
          p[o] = col[0]; p[o + 1] = col[1]; p[o + 2] = col[2];
        }
        p[o + 3] = 255;
      }
    } else {
      const scale = (0.18 * 100) / (12.5 * Math.pow(2, state.ev)); // src/output/png.rs ev_to_scale
      const lut = new Uint8ClampedArray(4097);
      for (let k = 0; k <= 4096; k++) lut[k] = Math.round(255 * encode(k / 4096));
      const X = ch.X || ch.Y, Y = ch.Y, Z = ch.Z || ch.Y;
      for (let i = 0; i < N; i++) {
        const x = X[i] * scale, y = Y[i] * scale, z = Z[i] * scale, o = 4 * i;
        for (let r = 0; r < 3; r++) {
          const v = ch.X && ch.Z ? M[r][0] * x + M[r][1] * y + M[r][2] * z : y;
          p[o + r] = lut[Math.round(Math.min(Math.max(v, 0), 1) * 4096)];
        }
        p[o + 3] = 255;
      }
    }
    ctx.putImageData(img, 0, 0);
    drawLegend();
    placeMarker();
    $("caption").textContent = state.fc
      ? `False colour of ${state.fcQ} (${state.fcScale} scale, ${state.palette}) of ${D.file}, ${W}×${H} pixels.`
      : `${D.file}, ${W}×${H} pixels, sRGB at ${fixed(state.ev, 1)} EV (ISO 100: ${sig(0.125 * Math.pow(2, state.ev), 3)} cd/m² shows as 18 % grey).`;
    $("image").setAttribute("aria-label", $("caption").textContent);
  }
  function drawLegend() {
    const L = $("legend");
    L.hidden = !state.fc;
    if (!state.fc) return;
    const s = currentScale(), unit = U()[state.fcQ].symbol;
    $("legend-title").textContent = `${state.fcQ} (${unit}), ${s.log ? "log" : "linear"} scale`;
    const bar = $("legend-bar"), g = bar.getContext("2d");
    for (let yb = 0; yb < bar.height; yb++) {
      const c = paletteColour(1 - yb / (bar.height - 1));
      g.fillStyle = `rgb(${c[0]},${c[1]},${c[2]})`;
      g.fillRect(0, yb, bar.width, 1);
    }
    const ol = $("legend-ticks");
    ol.replaceChildren();
    for (const t of s.ticks) {
      const li = document.createElement("li");
      li.textContent = sig(t, 4);
      li.style.bottom = `${100 * position(s, t)}%`;
      ol.appendChild(li);
    }
    $("legend-undefined").hidden = !(state.fcQ === "illuminance" && ch.E);
  }

  // ---- tables from the report JSON
  function cell(tag, text, attrs) {
    const e = document.createElement(tag);
    e.textContent = text;
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    return e;
  }
  function table2(headers, rows, caption) {
    const t = document.createElement("table");
    if (caption) t.appendChild(cell("caption", caption));
    const tr = document.createElement("tr");
    for (const h of headers) tr.appendChild(cell("th", h, { scope: "col" }));
    t.appendChild(document.createElement("thead")).appendChild(tr);
    const tb = t.appendChild(document.createElement("tbody"));
    for (const r of rows) {
      const row = tb.appendChild(document.createElement("tr"));
      r.forEach((v, k) => row.appendChild(cell(k === 0 ? "th" : "td", v, k === 0 ? { scope: "row" } : {})));
    }
    return t;
  }
  function renderGrids() {
    const R = D.report, box = $("grids");
    box.replaceChildren();
    if (!R || !R.grids || !R.grids.length) return;
    $("grids-section").hidden = false;
    const u = illUnit(), toD = (v) => fromSi("illuminance", siFromReport("illuminance", v));
    for (const g of R.grids) {
      const fig = box.appendChild(document.createElement("figure"));
      fig.className = "grid";
      const st = `E_min ${sig(toD(g.E_min), 4)} ${u}, E_avg ${sig(toD(g.E_avg), 4)} ${u}, E_max ${sig(toD(g.E_max), 4)} ${u}, U0 = E_min/E_avg ${g.U0 === null ? "undefined" : fixed(g.U0, 3)}, E_min/E_max ${g.E_min_over_E_max === null ? "undefined" : fixed(g.E_min_over_E_max, 3)}`;
      fig.appendChild(cell("figcaption", `grid “${g.name}”, ${g.nx}×${g.ny} points (${u}; row 0 at the bottom): ${st}`));
      const vals = g.values.flat().map(toD);
      const lo = Math.min(...vals), hi = Math.max(...vals);
      const t = fig.appendChild(document.createElement("table"));
      t.className = "heat";
      t.setAttribute("aria-label", `grid ${g.name} values in ${u}`);
      for (let j = g.ny - 1; j >= 0; j--) {
        const tr = t.appendChild(document.createElement("tr"));
        for (let i = 0; i < g.nx; i++) {
          const v = toD(g.values[j][i]);
          const c = D.palettes.turbo[Math.round(255 * (hi > lo ? (v - lo) / (hi - lo) : 0.5))];
          const td = cell("td", sig(v, 3));
          td.style.background = `rgb(${c[0]},${c[1]},${c[2]})`;
          td.style.color = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2] > 128 ? "#000" : "#fff";
          td.title = `(${i}, ${j}): ${sig(v, 5)} ± ${sig(2.131 * toD(g.stderr[j][i]), 3)} ${u}`;
          tr.appendChild(td);
        }
      }
      fig.appendChild(table2(["statistic", `value (${u})`], [
        ["E_min", sig(toD(g.E_min), 5)], ["E_avg", sig(toD(g.E_avg), 5)], ["E_max", sig(toD(g.E_max), 5)],
        ["U0 = E_min/E_avg", g.U0 === null ? "undefined" : fixed(g.U0, 3)],
        ["E_min/E_max", g.E_min_over_E_max === null ? "undefined" : fixed(g.E_min_over_E_max, 3)],
      ]));
    }
  }
  function renderMeters() {
    const R = D.report, box = $("meters");
    box.replaceChildren();
    if (!R || !R.meters || !R.meters.length) return;
    $("meters-section").hidden = false;
    const rows = R.meters.map((m) => {
      const q = m.kind === "luminance" ? "luminance" : "illuminance";
      const f = (v) => (v === null || v === undefined ? "" : sig(fromSi(q, siFromReport(q, v)), 5));
      return [m.name, m.kind, `${f(m.value)} ${U()[q].symbol}`, `${f(m.ci95_low)} … ${f(m.ci95_high)}`, String(m.samples)];
    });
    box.appendChild(table2(["meter", "kind", "value", "95 % interval", "samples"], rows));
  }
  function renderGlare() {
    const G = D.glare;
    if (!G) return;
    $("glare-section").hidden = false;
    const box = $("glare");
    box.replaceChildren();
    const iv = (x, d) => {
      if (!x || !Number.isFinite(x.value)) return "undefined";
      const ok = Array.isArray(x.ci95) && x.ci95.every(Number.isFinite);
      return ok ? `${fixed(x.value, d)} (95 %: ${fixed(x.ci95[0], d)} … ${fixed(x.ci95[1], d)})` : fixed(x.value, d);
    };
    box.appendChild(table2(["index", "value"], [
      ["DGP", iv(G.dgp, 3)], ["UGR", iv(G.ugr, 1)], ["DGI", iv(G.dgi, 1)], ["VCP", iv(G.vcp, 1)], ["CGI", iv(G.cgi, 1)],
      [`E_v (${illUnit()})`, Number.isFinite(G.ev_lx.value) ? sig(fromSi("illuminance", G.ev_lx.value), 5) : "undefined"],
    ], G.trustworthy === false ? "flagged untrustworthy: see the warnings of candela glare" : "glare indices"));
    box.appendChild(table2(["source", "direction (view frame)", `luminance (${lumUnit()})`, "solid angle (sr)", "angle from view (°)", "position index", `illuminance (${illUnit()})`, "pixels"],
      G.sources.map((s, k) => [String(k + 1), s.direction.map((c) => fixed(c, 3)).join(" "), sig(fromSi("luminance", s.luminance_cd_m2), 5),
        sig(s.solid_angle_sr, 4), fixed(s.angle_from_view_deg, 1), sig(s.position_index, 4), sig(fromSi("illuminance", s.illuminance_lx), 4), String(s.pixels)]),
      "glare sources"));
  }
  function renderRun() {
    const R = D.report, dl = $("run");
    dl.replaceChildren();
    const item = (k, v) => { if (v === undefined || v === null || v === "") return; dl.appendChild(cell("dt", k)); dl.appendChild(cell("dd", String(v))); };
    const A = D.attributes;
    item("image", `${D.file} (${W}×${H} pixels)`);
    item("scene", (R && R.scene) || A.scene);
    item("software", (R && `${R.software} ${R.version}`) || A.software);
    item("units", `${lumUnit()} (luminance), ${illUnit()} (illuminance); 1 fL = ${D.units.imperial.luminance.si_per_unit} cd/m², 1 fc = ${D.units.imperial.illuminance.si_per_unit} lx`);
    item("samples per pixel (mean)", A.spp);
    item("report page written by", `${D.generator.software} ${D.generator.version}`);
    if (R) {
      const s = R.settings || {}, t = R.timing || {}, p = R.progressive || {};
      item("settings", `spp ${s.spp}, max depth ${s.max_depth === null ? "unlimited" : s.max_depth}, seed ${s.seed}, threads ${s.threads}, illuminance ${s.illuminance}, caustics ${s.caustics}`);
      item("render time", t.render_seconds !== undefined ? `${fixed(t.render_seconds, 2)} s (meters and grids ${fixed(t.measure_seconds || 0, 2)} s)` : "");
      item("stopping reason", p.stop_reason !== undefined ? `${p.stop_reason} after ${p.passes} passes` : "");
      item("report created", R.created_utc);
      const ul = $("warnings");
      ul.replaceChildren();
      for (const w of R.warnings || []) ul.appendChild(cell("li", `warning: ${w}`));
    } else {
      item("render report", "none given: no settings, timing, meters or grids");
    }
  }
  function renderAll() { draw(); showProbe(); renderGrids(); renderMeters(); renderGlare(); renderRun(); }

  // ---- interaction
  function pixelAt(ev) {
    const r = $("image").getBoundingClientRect();
    const x = Math.floor(((ev.clientX - r.left) / r.width) * W), y = Math.floor(((ev.clientY - r.top) / r.height) * H);
    return x >= 0 && y >= 0 && x < W && y < H ? [x, y] : null;
  }
  function setProbe(p) { state.px = p; showProbe(); }
  function wire() {
    const c = $("image");
    c.addEventListener("mousemove", (e) => { if (!state.pinned) { const p = pixelAt(e); if (p) setProbe(p); } });
    c.addEventListener("click", (e) => { const p = pixelAt(e); if (p) { state.pinned = true; setProbe(p); } });
    c.addEventListener("keydown", (e) => {
      const step = e.shiftKey ? 10 : 1;
      const d = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step] }[e.key];
      let [x, y] = state.px || [Math.floor(W / 2), Math.floor(H / 2)];
      if (d) { x = Math.min(Math.max(x + d[0], 0), W - 1); y = Math.min(Math.max(y + d[1], 0), H - 1); state.pinned = true; }
      else if (e.key === "Enter" || e.key === " ") state.pinned = !state.pinned;
      else if (e.key === "Escape") state.pinned = false;
      else if (e.key === "Home") { x = 0; y = 0; }
      else return;
      e.preventDefault();
      setProbe([x, y]);
    });
    window.addEventListener("resize", placeMarker);
    c.addEventListener("focus", () => { if (state.px === null) setProbe([Math.floor(W / 2), Math.floor(H / 2)]); });
    const ev = $("ev");
    ev.value = state.ev;
    $("ev-out").textContent = `${fixed(state.ev, 1)} EV`;
    ev.addEventListener("input", () => { state.ev = parseFloat(ev.value); $("ev-out").textContent = `${fixed(state.ev, 1)} EV`; draw(); });
    $("ev-auto").addEventListener("click", () => { state.ev = D.auto_exposure_ev; ev.value = state.ev; $("ev-out").textContent = `${fixed(state.ev, 1)} EV`; draw(); });
    if (!ch.E) $("fc-q").querySelector('option[value="illuminance"]').disabled = true;
    const fillRange = () => { const s = currentScale(); $("fc-min").value = s.min; $("fc-max").value = s.max; };
    $("fc-on").addEventListener("change", (e) => { state.fc = e.target.checked; fillRange(); draw(); });
    $("fc-q").addEventListener("change", (e) => { state.fcQ = e.target.value; state.min = state.max = null; fillRange(); draw(); });
    $("fc-scale").addEventListener("change", (e) => { state.fcScale = e.target.value; state.min = state.max = null; fillRange(); draw(); });
    $("fc-palette").addEventListener("change", (e) => { state.palette = e.target.value; draw(); });
    const range = () => {
      const a = parseFloat($("fc-min").value), b = parseFloat($("fc-max").value);
      if (Number.isFinite(a) && Number.isFinite(b) && a < b && (state.fcScale !== "log" || a > 0)) { state.min = a; state.max = b; draw(); }
    };
    $("fc-min").addEventListener("change", range);
    $("fc-max").addEventListener("change", range);
    $("fc-auto").addEventListener("click", () => { state.min = state.max = null; fillRange(); draw(); });
    for (const r of document.querySelectorAll('input[name="units"]')) {
      r.addEventListener("change", (e) => { state.units = e.target.value; state.min = state.max = null; fillRange(); renderAll(); });
    }
  }

  async function main() {
    try {
      if (typeof DecompressionStream === "undefined") throw new Error("this browser has no DecompressionStream (use a current browser)");
      const planes = await Promise.all(D.channels.map(decode));
      D.channels.forEach((c, k) => { ch[c.name] = planes[k]; });
      D.channels = null; // the base64 text is no longer needed
      wire();
      renderAll();
      performance.mark("candela-image-drawn");
      $("status").textContent = `${W}×${H} pixels, channels ${Object.keys(ch).join(", ")}.`;
      document.body.dataset.ready = "1";
    } catch (e) {
      $("status").textContent = `The image could not be decoded: ${e.message}`;
      document.body.dataset.ready = "error";
      throw e;
    }
  }
  // For the tests and for anyone at the console: the formatting and the probe of a pixel.
  window.candelaReport = { sig, fixed, expo, probeText: (x, y) => probeText(x, y), state };
  main();
})();
