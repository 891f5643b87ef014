// spectrinsic dataset gallery: a static page over window.SPECTRINSIC_GALLERY (gallery-index.js).
// Renders one page of samples at a time; a sample view with a layer switcher, zoom, an A/B
// slider, colour bars, a linear pixel readout decoded from each preview's stated encoding,
// light SPDs and their CIE 1931 xy chromaticities. No network, no libraries.
"use strict";
(function () {
  const G = window.SPECTRINSIC_GALLERY;
  const PAGE_SIZE = 60;
  const SVG = "http://www.w3.org/2000/svg";
  const state = { scene: "", generator: "", condition: "", kind: "", split: "", noiseMax: "", residualMax: "", page: 0 };
  const app = document.getElementById("app");

  function el(tag, attrs, ...children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "on") for (const [ev, fn] of Object.entries(v)) node.addEventListener(ev, fn);
      else if (k === "text") node.textContent = v;
      else node.setAttribute(k, v);
    }
    for (const c of children) if (c != null) node.append(c);
    return node;
  }
  function svg(tag, attrs, ...children) {
    const node = document.createElementNS(SVG, tag);
    for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
    for (const c of children) if (c != null) node.append(c);
    return node;
  }
  const uniq = (key) => [...new Set(G.samples.map((s) => s[key]).filter((v) => v != null))].sort();
  const fmt = (v) => (v === 0 ? "0" : Math.abs(v) >= 1e4 || Math.abs(v) < 1e-3 ? v.toExponential(3) : v.toPrecision(4));

  // ------------------------------------------------------------------ decoding of previews
  const srgbDecode = (c) => (c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4));
  // The linear value an 8-bit code stands for, with the half-width of its quantisation step.
  function decodeSrgb(code, scale) {
    const lo = srgbDecode(Math.max(code - 0.5, 0) / 255), hi = srgbDecode(Math.min(code + 0.5, 255) / 255);
    return { value: srgbDecode(code / 255) / scale, precision: (hi - lo) / 2 / scale,
             clipped: code >= 255, under: code <= 0, clip: 1 / scale };
  }
  // A colormap preview's colour -> its value. matplotlib maps t = (v - vmin) / span to colour
  // floor(256 t) (clipped to 0..255), so colour i stands for t in [i/256, (i+1)/256).
  function decodeColormap(rgb, enc) {
    const lut = G.colormaps[enc.cmap];
    let best = 0, dist = Infinity;
    for (let i = 0; i < lut.length; i++) {
      const d = (lut[i][0] - rgb[0]) ** 2 + (lut[i][1] - rgb[1]) ** 2 + (lut[i][2] - rgb[2]) ** 2;
      if (d < dist) { dist = d; best = i; }
    }
    const span = enc.vmax - enc.vmin;
    return { value: enc.vmin + ((best + 0.5) / 256) * span, precision: span / 512,
             clipped: best === 255, under: best === 0, onMap: dist <= 3 };
  }
  function describe(layer, rgb, enc) {
    if (!enc || enc.kind === "categorical") {
      return { text: `${layer}: rgb8 ${rgb.join(", ")} (categorical preview: no scalar value)`, values: null };
    }
    if (enc.kind === "srgb") {
      const d = [0, 1, 2].map((i) => decodeSrgb(rgb[i], enc.scale));
      const parts = d.map((x) => (x.clipped ? `≥ ${fmt(x.clip)} (≥ clip)` : x.under ? `≤ ${fmt(x.precision)} (≤ 0 clips)`
        : `${fmt(x.value)} ± ${fmt(x.precision)}`));
      return { text: `${layer}: R ${parts[0]}  G ${parts[1]}  B ${parts[2]}  (sRGB preview × ${fmt(enc.scale)})`,
               values: d.map((x) => x.value), precision: d.map((x) => x.precision), clipped: d.map((x) => x.clipped),
               under: d.map((x) => x.under) };
    }
    const d = decodeColormap(rgb, enc);
    if (!d.onMap) return { text: `${layer}: rgb8 ${rgb.join(", ")} is off the ${enc.cmap} colour map (masked: no value)`, values: null };
    const txt = d.clipped ? `≥ ${fmt(d.value - d.precision)} (≥ clip)` : d.under ? `≤ ${fmt(d.value + d.precision)}`
      : `${fmt(d.value)} ± ${fmt(d.precision)}`;
    return { text: `${layer}: ${txt}  (${enc.cmap} ${fmt(enc.vmin)}–${fmt(enc.vmax)}${enc.of ? ", " + enc.of : ""})`,
             values: [d.value], precision: [d.precision], clipped: [d.clipped], under: [d.under] };
  }

  // ------------------------------------------------------------------ overview
  function filtered() {
    const max = state.noiseMax === "" ? Infinity : parseFloat(state.noiseMax);
    const rmax = state.residualMax === "" ? Infinity : parseFloat(state.residualMax);
    return G.samples.filter((s) => (!state.scene || s.scene === state.scene)
      && (!state.generator || s.generator === state.generator)
      && (!state.condition || s.condition === state.condition)
      && (!state.kind || s.kind === state.kind)
      && (!state.split || s.split === state.split)
      && (max === Infinity || (s.noise != null && s.noise <= max))
      && (rmax === Infinity || (s.residual_share != null && s.residual_share <= rmax)));
  }
  function select(key, label, values) {
    const s = el("select", { id: `filter-${key}`, on: { change: (e) => { state[key] = e.target.value; state.page = 0; renderList(); } } },
      el("option", { value: "", text: `all (${values.length})` }), ...values.map((v) => el("option", { value: v, text: v })));
    s.value = state[key];
    return el("label", {}, label, s);
  }
  function filterBar() {
    const bar = el("div", { class: "filters" }, select("scene", "scene", uniq("scene")),
      select("generator", "generator", uniq("generator")), select("condition", "condition", uniq("condition")), select("kind", "kind", uniq("kind")));
    if (G.splits.length) bar.append(select("split", "split", G.splits));
    const noise = el("input", { id: "filter-noise", type: "number", step: "0.001", min: "0", placeholder: "any",
      on: { change: (e) => { state.noiseMax = e.target.value; state.page = 0; renderList(); } } });
    noise.value = state.noiseMax;
    bar.append(el("label", { title: "median relative standard error of shading_raw" }, "noise ≤", noise));
    const residual = el("input", { id: "filter-residual", type: "number", step: "0.01", min: "0", placeholder: "any",
      on: { change: (e) => { state.residualMax = e.target.value; state.page = 0; renderList(); } } });
    residual.value = state.residualMax;
    bar.append(el("label", { title: "share of the image in the RGB residual, sum |residual| / sum |image| over the mask" }, "residual ≤", residual));
    return bar;
  }
  function overviewPanels() {
    const sheets = el("div", { class: "sheets" }, ...Object.entries(G.contact_sheets).map(([cond, src]) =>
      el("figure", {}, el("a", { href: src }, el("img", { src, loading: "lazy", alt: `contact sheet ${cond}` })),
        el("figcaption", { text: cond }))));
    const out = [el("details", { class: "overview", id: "contact-sheets" }, el("summary", { text: "Contact sheets per condition" }), sheets)];
    if (G.summary_plots.length) {
      out.push(el("details", { class: "overview", id: "summary-plots" }, el("summary", { text: "Summary plots" }),
        ...G.summary_plots.map((src) => el("figure", {}, el("img", { src, loading: "lazy", alt: src }), el("figcaption", { text: src })))));
    }
    return out;
  }
  function card(s) {
    const thumb = s.layers[s.first_layer] ? s.layers[s.first_layer][0] : Object.values(s.layers)[0][0];
    return el("div", { class: "card", "data-id": s.id, on: { click: () => { location.hash = "sample=" + encodeURIComponent(s.id); } } },
      el("img", { src: thumb, loading: "lazy", alt: s.id, width: "160", height: "160" }),
      el("div", { class: "id", text: s.id }),
      el("div", { class: "sub", text: `${s.condition ?? ""} · ${s.kind ?? ""}${s.noise != null ? " · noise " + fmt(s.noise) : ""}${s.residual_share != null ? " · residual " + fmt(s.residual_share) : ""}${s.split ? " · " + s.split : ""}` }));
  }
  function renderList() {
    const list = filtered();
    const pages = Math.max(1, Math.ceil(list.length / PAGE_SIZE));
    state.page = Math.min(state.page, pages - 1);
    const page = list.slice(state.page * PAGE_SIZE, (state.page + 1) * PAGE_SIZE);
    const go = (d) => () => { state.page = Math.min(pages - 1, Math.max(0, state.page + d)); renderList(); };
    const pager = el("div", { class: "pager" }, el("button", { id: "prev", text: "‹ prev", on: { click: go(-1) } }),
      el("span", { id: "page-info", text: `page ${state.page + 1} of ${pages} · ${list.length} of ${G.samples.length} samples` }),
      el("button", { id: "next", text: "next ›", on: { click: go(1) } }));
    document.getElementById("list").replaceChildren(pager, el("div", { class: "grid", id: "grid" }, ...page.map(card)));
  }
  function renderOverview() {
    app.replaceChildren(filterBar(), ...overviewPanels(), el("div", { id: "list" }));
    renderList();
  }

  // ------------------------------------------------------------------ one sample
  function colourBar(enc) {
    if (!enc || enc.kind !== "colormap") return null;
    const c = el("canvas", { width: "256", height: "1" });
    const ctx = c.getContext("2d");
    const img = ctx.createImageData(256, 1);
    G.colormaps[enc.cmap].forEach((rgb, i) => img.data.set([...rgb, 255], 4 * i));
    ctx.putImageData(img, 0, 0);
    const ticks = el("div", { class: "ticks" });
    for (let i = 0; i <= 4; i++) {
      ticks.append(el("span", { style: `left:${i * 25}%`, text: fmt(enc.vmin + (i / 4) * (enc.vmax - enc.vmin)) }));
    }
    return el("div", { class: "colourbar" }, c, ticks);
  }
  function spdPlot(light) {
    const w = 260, h = 150, p = 28, spd = light.spd || [];
    const max = Math.max(...spd, 1e-12);
    const start = G.spd_grid.start_nm, step = G.spd_grid.step_nm, end = start + step * (spd.length - 1);
    const x = (nm) => p + ((nm - start) / (end - start || 1)) * (w - 2 * p);
    const y = (v) => h - p - (v / max) * (h - 2 * p);
    const pts = spd.map((v, i) => `${x(start + i * step).toFixed(1)},${y(v).toFixed(1)}`).join(" ");
    const s = svg("svg", { width: w, height: h, viewBox: `0 0 ${w} ${h}`, class: "spd", role: "img" },
      svg("polyline", { points: `${p},${p} ${p},${h - p} ${w - p},${h - p}`, fill: "none", stroke: "#999" }),
      svg("polyline", { points: pts, fill: "none", stroke: "#c30", "stroke-width": "1.5" }));
    for (const nm of [400, 500, 600, 700]) {
      s.append(svg("text", { x: x(nm), y: h - p + 12, "font-size": "9", "text-anchor": "middle" }, String(nm)));
    }
    s.append(svg("text", { x: w / 2, y: h - 4, "font-size": "9", "text-anchor": "middle" }, "wavelength (nm)"),
      svg("text", { x: 4, y: p - 8, "font-size": "9" }, `${light.name ?? "light"}: ${light.spectrum} (relative SPD)`));
    return s;
  }
  function cieDiagram(lights) {
    const w = 220, h = 240, p = 24;
    const x = (v) => p + (v / 0.8) * (w - 2 * p), y = (v) => h - p - (v / 0.9) * (h - 2 * p);
    const poly = (pts) => pts.map(([a, b]) => `${x(a).toFixed(1)},${y(b).toFixed(1)}`).join(" ");
    const s = svg("svg", { width: w, height: h, viewBox: `0 0 ${w} ${h}`, class: "cie", role: "img", "aria-label": "CIE 1931 xy chromaticities" },
      svg("polyline", { points: `${x(0)},${y(0.9)} ${x(0)},${y(0)} ${x(0.8)},${y(0)}`, fill: "none", stroke: "#999" }),
      svg("polygon", { points: poly(G.locus), fill: "#f2f2f2", stroke: "#333" }),
      svg("polygon", { points: poly(G.srgb.primaries), fill: "none", stroke: "#888", "stroke-dasharray": "3,2" }, svg("title", {}, "sRGB gamut")),
      svg("circle", { cx: x(G.srgb.white[0]), cy: y(G.srgb.white[1]), r: 2, fill: "#000" }, svg("title", {}, "D65")),
      svg("text", { x: w - p, y: h - 6, "font-size": "9" }, "x"), svg("text", { x: 4, y: p, "font-size": "9" }, "y"));
    for (const l of lights) {
      if (!l.xy) continue;
      const rgb = (l.srgb || [1, 1, 1]).map((v) => Math.max(v, 0));
      const peak = Math.max(...rgb, 1e-12);
      const hex = rgb.map((v) => Math.round(255 * Math.pow(v / peak, 1 / 2.2))).map((v) => v.toString(16).padStart(2, "0")).join("");
      s.append(svg("circle", { cx: x(l.xy[0]).toFixed(1), cy: y(l.xy[1]).toFixed(1), r: 5, fill: "#" + hex, stroke: "#000", class: "light-dot" },
        svg("title", {}, `${l.name ?? "light"}: ${l.spectrum} (x=${l.xy[0].toFixed(4)}, y=${l.xy[1].toFixed(4)})`)));
    }
    return s;
  }

  // Pixels of each preview, read once through a canvas. A page opened from file:// may not
  // read its own images in Chromium (a tainted canvas); the gallery then loads the sample's
  // gallery-pixels/<id>.js, which holds the same PNGs as data: URLs, which a canvas may read.
  const pixelCache = new Map();
  const pixelScripts = new Map();
  let filesReadable = true;
  function readCanvas(img) {
    try {
      const c = document.createElement("canvas");
      c.width = img.naturalWidth; c.height = img.naturalHeight;
      const ctx = c.getContext("2d", { willReadFrequently: true });
      ctx.drawImage(img, 0, 0);
      return { w: c.width, h: c.height, rgba: ctx.getImageData(0, 0, c.width, c.height).data };
    } catch (e) {
      return null;
    }
  }
  function embeddedPixels(s, n, redraw) {
    const all = (window.SPECTRINSIC_PIXELS || {})[s.id];
    if (!all) {
      if (s.pixels && !pixelScripts.has(s.id)) {
        const tag = el("script", { src: s.pixels });
        tag.addEventListener("load", redraw);
        pixelScripts.set(s.id, tag);
        document.head.append(tag);
      }
      return s.pixels ? "pending" : null;
    }
    if (!all[n]) return null;
    const key = `${s.id}|${n}`;
    pixelCache.set(key, "pending");
    const im = new Image();
    im.addEventListener("load", () => { pixelCache.set(key, readCanvas(im)); redraw(); });
    im.src = all[n];
    return "pending";
  }
  // {w, h, rgba, source}, "pending" (asked for; redraw() runs when it comes) or null (none).
  function pixels(s, n, img, redraw) {
    const key = `${s.id}|${n}`;
    if (pixelCache.has(key)) return pixelCache.get(key);
    if (filesReadable) {
      if (!(img.complete && img.naturalWidth)) { img.addEventListener("load", redraw, { once: true }); return "pending"; }
      const data = readCanvas(img);
      if (data) { data.source = "file"; pixelCache.set(key, data); return data; }
      filesReadable = false;
    }
    const data = embeddedPixels(s, n, redraw);
    if (data && data !== "pending") data.source = "embedded";
    return data;
  }
  function readoutAt(s, layers, px, py, redraw) {
    const lines = [`pixel x=${px} y=${py}`];
    const report = { x: px, y: py, layers: {}, source: null };
    for (const [img, n] of layers) {
      const data = pixels(s, n, img, redraw);
      if (data === "pending") { lines.push(`${n}: loading pixel values…`); continue; }
      if (!data) { lines.push(`${n}: no pixel values (serve the folder, python -m http.server, or rebuild the gallery)`); continue; }
      const o = 4 * (py * data.w + px);
      const d = describe(n, [data.rgba[o], data.rgba[o + 1], data.rgba[o + 2]], s.layers[n][1]);
      lines.push(d.text);
      report.layers[n] = d;
      report.source = data.source || "embedded";
    }
    return { text: lines.join("\n"), report };
  }

  function renderSample(id) {
    const s = G.samples.find((x) => x.id === id);
    if (!s) { renderOverview(); return; }
    const names = Object.keys(s.layers);
    // image_denoised first where it exists (the index orders it first); B: the raw render beside it
    const view = { a: s.first_layer in s.layers ? s.first_layer : names[0], b: null, zoom: 1, split: 50 };
    view.b = ["image", "image_rgb3", "image_denoised", "shading_raw"].find((n) => n in s.layers && n !== view.a) || view.a;
    const imgA = el("img", { class: "a", alt: "layer A" }), imgB = el("img", { class: "b", alt: "layer B" });
    const divider = el("div", { class: "divider" });
    const stack = el("div", { class: "stack" }, imgA, imgB, divider);
    const viewer = el("div", { class: "viewer", id: "viewer", title: "click to zoom in (×2, up to ×16, then back); shift-click to zoom out" }, stack);
    const readout = el("div", { class: "readout", id: "readout", text: "move the cursor over the image for linear values" });
    const slider = el("input", { type: "range", id: "ab-slider", min: "0", max: "100", value: "50" });
    const bSelect = el("select", { id: "layer-b" }, ...names.map((n) => el("option", { value: n, text: n })));
    const bars = el("div", { id: "colourbars" });
    const units = el("div", { class: "meta-line", id: "units" });
    const buttons = el("div", { class: "layers", id: "layers" }, ...names.map((n) => el("button", { "data-layer": n, text: n,
      on: { click: () => { view.a = n; update(); } } })));
    function size() {
      const w = imgA.naturalWidth || (s.size ? s.size[1] : 256), h = imgA.naturalHeight || (s.size ? s.size[0] : 256);
      const base = Math.max(1, Math.floor(512 / Math.max(w, h)));
      for (const im of [imgA, imgB]) { im.style.width = `${w * base * view.zoom}px`; im.style.height = `${h * base * view.zoom}px`; }
    }
    function clip() {
      imgB.style.clipPath = `inset(0 0 0 ${view.split}%)`;
      divider.style.left = `${view.split}%`;
    }
    function update() {
      imgA.src = s.layers[view.a][0]; imgB.src = s.layers[view.b][0];
      bSelect.value = view.b;
      for (const b of buttons.children) { b.classList.toggle("on", b.dataset.layer === view.a); b.classList.toggle("onb", b.dataset.layer === view.b); }
      bars.replaceChildren(...[["A", view.a], ["B", view.b]].map(([k, n]) => {
        const bar = colourBar(s.layers[n][1]);
        return bar ? el("div", {}, el("div", { text: `${k}: ${n}` }), bar) : null;
      }).filter(Boolean));
      const info = (n) => (G.layer_info[n] || {}).units || "";
      units.textContent = `A: ${view.a} — ${info(view.a)}\nB: ${view.b} — ${info(view.b)}`;
      clip();
    }
    imgA.addEventListener("load", size);
    bSelect.addEventListener("change", (e) => { view.b = e.target.value; update(); });
    slider.addEventListener("input", (e) => { view.split = parseFloat(e.target.value); clip(); });
    viewer.addEventListener("click", (e) => { view.zoom = e.shiftKey ? Math.max(1, view.zoom / 2) : view.zoom >= 16 ? 1 : view.zoom * 2; size(); });
    let last = null;
    function onMove(e) {
      last = e;
      const r = imgA.getBoundingClientRect();
      const px = Math.floor(((e.clientX - r.left) / r.width) * imgA.naturalWidth);
      const py = Math.floor(((e.clientY - r.top) / r.height) * imgA.naturalHeight);
      if (px < 0 || py < 0 || px >= imgA.naturalWidth || py >= imgA.naturalHeight) return;
      const layers = view.a === view.b ? [[imgA, view.a]] : [[imgA, view.a], [imgB, view.b]];
      const out = readoutAt(s, layers, px, py, () => { if (last === e) onMove(e); });
      readout.textContent = out.text;
      readout.dataset.report = JSON.stringify(out.report);
    }
    stack.addEventListener("mousemove", onMove);
    const links = el("div", { class: "files" }, "files: ", ...s.files.map((f) => el("a", { href: f, text: f.split("/").pop() })));
    const lights = el("div", { class: "lights", id: "lights" }, ...s.lights.map(spdPlot), cieDiagram(s.lights));
    const shares = s.lights.map((l) => `${l.name} ${l.share != null ? (100 * l.share).toFixed(1) + " %" : "—"}`).join(", ");
    const step = (id, text, target) => target
      ? el("a", { href: "#sample=" + encodeURIComponent(target), id, text, title: target })
      : el("span", { id, class: "disabled", text });
    const nav = el("p", { class: "nav" }, el("a", { href: "#", id: "back", text: "‹ back to the overview" }), " · ",
      step("prev-sample", "‹ previous sample", s.prev), " · ", step("next-sample", "next sample ›", s.next));
    // every layer of this sample at once; a click shows it as layer A above
    const grid = el("div", { class: "layer-grid", id: "layer-grid" }, ...names.map((n) => el("figure", { "data-layer": n,
      on: { click: () => { view.a = n; update(); window.scrollTo(0, 0); } } },
      el("img", { src: s.layers[n][0], loading: "lazy", alt: n }), el("figcaption", { text: n }))));
    // the camera chain in the order light goes through it (dataset --camera), a click shows a layer as A
    const sensor = s.sensor && s.sensor.layers.length ? [el("h3", { text: `Camera chain: ${s.sensor.camera}` }),
      el("p", { class: "meta-line", text: "exposure metered on the lit pixels' median luminance"
        + (s.sensor.electrons_per_unit != null ? ` (${Number(s.sensor.electrons_per_unit).toPrecision(4)} e- per unit)` : "") }),
      el("div", { class: "layer-grid", id: "sensor-panel" }, ...s.sensor.layers.map(([n, caption]) => el("figure", { "data-layer": n,
        on: { click: () => { view.a = n; update(); window.scrollTo(0, 0); } } },
        el("img", { src: s.layers[n][0], loading: "lazy", alt: n }), el("figcaption", { text: caption }))))] : [];
    app.replaceChildren(el("div", { class: "sample", id: "sample", "data-id": s.id },
      nav,
      el("h2", { text: s.id }),
      el("p", { class: "meta-line", id: "sample-meta", text: `scene ${s.scene} · condition ${s.condition} · kind ${s.kind} · render ${s.reference_mode}`
        + ` · light shares ${shares}`
        + (s.noise != null ? ` · noise (shading_raw median) ${fmt(s.noise)}` : "") + (s.split ? ` · split ${s.split}` : "") }),
      buttons,
      el("div", { class: "ab" }, "A/B: A = the selected layer (left), B =", bSelect, slider),
      el("div", { class: "viewer-row" }, viewer, el("div", { class: "side" }, readout, bars, units)),
      ...sensor, el("h3", { text: "Lights" }), lights, el("h3", { text: "All layers" }), grid, links));
    update();
    size();
  }

  function route() {
    const m = location.hash.match(/^#sample=(.+)$/);
    if (m) renderSample(decodeURIComponent(m[1])); else renderOverview();
    window.scrollTo(0, 0);
  }
  if (!G) { app.textContent = "gallery-index.js is missing: rebuild the gallery (spectrinsic dataset)."; return; }
  window.addEventListener("hashchange", route);
  route();
  performance.mark("gallery-rendered"); // the first view is in the DOM (for measuring first paint)
})();
