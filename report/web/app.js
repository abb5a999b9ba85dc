// saresgs report: draws the page from the JSON the report writer embeds
// (the script element "saresgs-data"). Every string from the data reaches the page as text
// (textContent, attribute values), never as markup. Plain browser JavaScript, no imports:
// compiled into the saresgs library (report/CMakeLists.txt); the 3D viewer is a separate
// bundle (window.SaresgsViewer) that may be absent.
(function () {
  "use strict";

  const data = JSON.parse(document.getElementById("saresgs-data").textContent);
  const app = document.getElementById("app");
  const report = { data, ready: null, viewer: null };
  window.saresgsReport = report;

  // ---- small DOM helpers -------------------------------------------------------------
  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v == null) continue;
      if (k === "class") e.className = v;
      else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, String(v));
    }
    for (const c of children.flat()) {
      if (c == null || c === false) continue;
      e.append(c instanceof Node ? c : document.createTextNode(String(c)));
    }
    return e;
  }
  const SVG = "http://www.w3.org/2000/svg";
  function svg(tag, attrs, ...children) {
    const e = document.createElementNS(SVG, tag);
    for (const [k, v] of Object.entries(attrs || {})) if (v != null) e.setAttribute(k, String(v));
    for (const c of children.flat()) if (c != null) e.append(c instanceof Node ? c : document.createTextNode(String(c)));
    return e;
  }
  const fmt = (v, d = 2) => (v == null || !Number.isFinite(v) ? "n/a" : v.toFixed(d));
  const section = (id, title, ...body) => el("section", { id }, el("h2", {}, title), ...body);

  // A table whose columns sort on a click (numbers by their data-value, text otherwise).
  function sortableTable(columns, rows, attrs) {
    const thead = el("thead", {}, el("tr", {}, columns.map((c, i) => el("th", { "data-col": i, title: "sort" }, c.title))));
    const tbody = el("tbody", {}, rows);
    const table = el("table", Object.assign({ class: "sortable" }, attrs || {}), thead, tbody);
    let state = { col: -1, dir: 1 };
    thead.addEventListener("click", (e) => {
      const th = e.target.closest("th");
      if (!th) return;
      const col = Number(th.getAttribute("data-col"));
      state = { col, dir: state.col === col ? -state.dir : 1 };
      const key = (tr) => {
        const td = tr.children[col];
        const v = td.getAttribute("data-value");
        return v != null && v !== "" && !Number.isNaN(Number(v)) ? Number(v) : td.textContent;
      };
      const sorted = Array.from(tbody.children).sort((a, b) => {
        const x = key(a);
        const y = key(b);
        return (typeof x === "number" && typeof y === "number" ? x - y : String(x).localeCompare(String(y))) * state.dir;
      });
      tbody.append(...sorted);
    });
    return table;
  }
  function cell(value, digits) {
    return el("td", { "data-value": value == null ? "" : value, class: typeof value === "number" ? "num" : null }, typeof value === "number" ? fmt(value, digits) : value == null ? "n/a" : value);
  }

  // A line chart: series [{name, points: [[x, y], ...], cls}], drawn as SVG, every point
  // carrying its numbers (data-x, data-y) so that a reader or a test can take them back.
  function lineChart(series, opts) {
    const W = 640, H = 300, L = 56, R = 16, T = 16, B = 44;
    const pts = series.flatMap((s) => s.points);
    if (!pts.length) return el("p", { class: "muted" }, "No points to draw.");
    let [x0, x1] = [Math.min(...pts.map((p) => p[0])), Math.max(...pts.map((p) => p[0]))];
    let [y0, y1] = [Math.min(...pts.map((p) => p[1])), Math.max(...pts.map((p) => p[1]))];
    if (x1 === x0) x1 = x0 + 1;
    const pad = (y1 - y0) * 0.08 || 0.5;
    y0 -= pad;
    y1 += pad;
    const X = (x) => L + ((x - x0) / (x1 - x0)) * (W - L - R);
    const Y = (y) => T + (1 - (y - y0) / (y1 - y0)) * (H - T - B);
    const g = svg("svg", { viewBox: `0 0 ${W} ${H}`, class: "chart", role: "img", "aria-label": opts.label });
    for (let k = 0; k <= 4; ++k) {
      const y = y0 + ((y1 - y0) * k) / 4;
      g.append(svg("line", { x1: L, x2: W - R, y1: Y(y), y2: Y(y), class: "grid" }));
      g.append(svg("text", { x: L - 6, y: Y(y) + 4, class: "tick", "text-anchor": "end" }, fmt(y, 1)));
    }
    const xs = Array.from(new Set(pts.map((p) => p[0]))).sort((a, b) => a - b);
    const step = Math.max(1, Math.ceil(xs.length / 12));
    xs.forEach((x, k) => {
      if (k % step === 0) g.append(svg("text", { x: X(x), y: H - B + 16, class: "tick", "text-anchor": "middle" }, x));
    });
    g.append(svg("text", { x: (L + W - R) / 2, y: H - 6, class: "axis", "text-anchor": "middle" }, opts.xLabel));
    g.append(svg("text", { x: 14, y: (T + H - B) / 2, class: "axis", "text-anchor": "middle", transform: `rotate(-90 14 ${(T + H - B) / 2})` }, opts.yLabel));
    series.forEach((s, si) => {
      const cls = s.cls || `series${si % 6}`;
      if (s.points.length > 1 && !s.markersOnly)
        g.append(svg("polyline", { points: s.points.map((p) => `${X(p[0])},${Y(p[1])}`).join(" "), class: `line ${cls}` }));
      for (const p of s.points) {
        const c = svg("circle", { cx: X(p[0]), cy: Y(p[1]), r: s.markersOnly ? 5 : 3, class: `dot ${cls}`, "data-series": s.name, "data-x": p[0], "data-y": p[1] });
        c.append(svg("title", {}, `${s.name}: ${fmt(p[1], 2)} at ${p[0]}`));
        g.append(c);
      }
    });
    const legend = el("div", { class: "legend" }, series.map((s, si) => el("span", { class: `key ${s.cls || `series${si % 6}`}` }, s.name)));
    return el("figure", { class: "chart-box" }, g, legend);
  }

  // ---- the run page ------------------------------------------------------------------
  function runPage() {
    const r = data.results;
    const ff = r.final_fit || null;
    document.title = `saresgs report: ${data.title}`;
    app.append(
      el("header", {}, el("h1", {}, data.title), el("p", { class: "muted" }, `${r.method}, preset ${r.preset}, seed ${r.seed}, ${r.threads} threads; dataset ${r.dataset}; run folder ${data.run_dir}`)),
    );
    const cards = [
      ff ? ["final fit PSNR", fmt(ff.psnr), "dB, test views"] : null,
      ff ? ["final fit SSIM", fmt(ff.ssim, 4), ""] : null,
      ["in-loop PSNR", fmt(r.psnr), "dB (paper's protocol)"],
      ["views held", String(r.selected_view_indices.length), `${r.initial_views.length} initial + ${r.selected_views.length} chosen`],
      ["Gaussians", String(r.gaussians), "in the loop's model"],
      ["time", fmt(r.seconds.end_to_end_this_process, 0), "s end to end"],
      r.ause != null ? ["AUSE", fmt(r.ause, 3), "uncertainty vs depth error"] : null,
    ].filter(Boolean);
    app.append(el("div", { class: "cards" }, cards.map(([k, v, u]) => el("div", { class: "card" }, el("div", { class: "k" }, k), el("div", { class: "v" }, v), el("div", { class: "u" }, u)))));
    if (data.missing.length)
      app.append(el("div", { class: "missing", id: "missing" }, el("strong", {}, "Not shown, and why:"), el("ul", {}, data.missing.map((m) => el("li", {}, m)))));
    for (const n of data.notes) app.append(el("p", { class: "note" }, n));

    app.append(modelSection());
    app.append(curveSection());
    app.append(viewsSection());
    app.append(stepsSection());
    app.append(runDetails());
  }

  function modelSection() {
    const m = data.model || {};
    const box = el("div", { class: "viewer-box" });
    const sec = section("model", "The model and the cameras", box);
    const sizeMb = m.bytes != null ? (m.bytes / 1048576).toFixed(1) : null;
    if (m.file) sec.append(el("p", { class: "muted", id: "model-info" }, `${m.which} (${m.file}): ${m.gaussians} Gaussians, SH degree ${m.sh_degree}; in this page as ${m.format}, ${sizeMb} MB (${m.note}). Drag to orbit, scroll to zoom, click a camera to look through it.`));
    const legend = el("div", { class: "legend" }, ["initial", "chosen", "test", "candidate"].map((k) => el("span", { class: `key role-${k}` }, k === "chosen" ? "chosen (numbered in order)" : k === "initial" ? "held at the start" : k)));
    sec.append(legend);
    const picked = el("p", { id: "picked", class: "muted" }, "");
    const overviewButton = el("button", { type: "button", id: "overview" }, "see every camera from outside");
    overviewButton.addEventListener("click", () => report.viewer && report.viewer.overview());
    sec.append(overviewButton, picked);
    const modelEl = document.getElementById("saresgs-model");
    if (!window.SaresgsViewer || !modelEl || !data.cameras.length) {
      box.append(el("p", { class: "missing" }, !window.SaresgsViewer ? "The 3D viewer is not in this page (see above)." : !modelEl ? "No model to show." : "No cameras: the dataset could not be read."));
      report.ready = Promise.resolve(null);
      return sec;
    }
    const canvas = el("canvas", { id: "viewer", width: 960, height: 540 });
    box.append(canvas);
    const b = atob(modelEl.textContent.trim());
    const bytes = new Uint8Array(b.length);
    for (let i = 0; i < b.length; ++i) bytes[i] = b.charCodeAt(i);
    const bg = (data.dataset && data.dataset.background) || [0, 0, 0];
    const startCamera = Math.max(0, data.cameras.findIndex((c) => c.role === "test"));
    report.ready = window.SaresgsViewer.createViewer(canvas, {
      model: { bytes, type: m.format },
      cameras: data.cameras,
      background: bg,
      startCamera,
      onPick: (i) => {
        const c = data.cameras[i];
        picked.textContent = `Looking through ${c.name} (${c.role}${c.order != null ? ` #${c.order}` : ""}).`;
      },
    }).then((v) => {
      report.viewer = v;
      return v;
    }, (e) => {
      box.append(el("p", { class: "missing" }, `The viewer failed: ${e && e.message ? e.message : e}`));
      throw e;
    });
    return sec;
  }

  function curveSection() {
    const r = data.results;
    const pts = (r.steps || []).map((s) => [s.views_before, s.progress_psnr]);
    const series = [{ name: "in the loop (progress test views)", points: pts, cls: "series0" }];
    const n = r.selected_view_indices.length;
    series.push({ name: "in-loop model, all test views", points: [[n, r.psnr]], markersOnly: true, cls: "series1" });
    if (r.final_fit) series.push({ name: "final fit, all test views", points: [[n, r.final_fit.psnr]], markersOnly: true, cls: "series2" });
    // the grid's other methods on the same scene and seed
    (data.baselines || []).forEach((b, i) => series.push({ name: `${b.name} (same scene and seed)`, points: b.points, cls: `series${3 + (i % 3)}` }));
    const sec = section("curve", "How the model improved, view by view", lineChart(series, { xLabel: "views held", yLabel: "PSNR (dB)", label: "PSNR against views held" }));
    const ssim = [`in-loop SSIM ${fmt(r.ssim, 4)}`];
    if (r.final_fit) ssim.push(`final fit SSIM ${fmt(r.final_fit.ssim, 4)}`);
    sec.append(el("p", { class: "muted" }, `Each step trains, then measures the test views before choosing the next one. ${ssim.join(", ")} (SSIM is measured at the end only).`));
    return sec;
  }

  function viewsSection() {
    const views = data.views.slice().sort((a, b) => a.psnr - b.psnr);
    const m = data.model || {};
    const shown = m.which || "the model";
    const cols = [
      { title: "view" }, { title: `PSNR (${shown})` }, { title: "SSIM" }, { title: "in-loop PSNR" }, { title: "depth error" }, { title: "nearest held view" }, { title: "truth | render | error" },
    ];
    const rows = views.map((v) =>
      el("tr", { "data-view": v.name },
        el("td", { "data-value": v.name }, v.name),
        cell(v.psnr, 2), cell(v.ssim, 4), cell(v.loop_psnr, 2), cell(v.depth_error, 4), cell(v.nearest_held, 3),
        el("td", { class: "pics" },
          v.truth ? el("img", { src: v.truth, alt: `${v.name} truth` }) : null,
          v.render ? el("img", { src: v.render, alt: `${v.name} render` }) : null,
          v.error ? el("img", { src: v.error, alt: `${v.name} error` }) : null,
          v.problem ? el("span", { class: "missing" }, v.problem) : null)));
    return section("views", "Every test view, worst first",
      el("p", { class: "muted" }, `Error: mean |render - truth| over RGB, black 0 to pale yellow ${data.error_scale} and above. Depth error: mean |depth - true depth| where the truth has depth, in the dataset's units. Nearest held view: distance from the camera to the closest view trained on.`),
      sortableTable(cols, rows, { id: "views-table" }));
  }

  // Why each view was chosen: a step's candidates coloured by their score.
  function stepsSection() {
    const r = data.results;
    const steps = (r.steps || []).filter((s) => s.selected);
    const sec = section("steps", "Why each view was chosen");
    if (!steps.length) {
      sec.append(el("p", { class: "muted" }, "This run chose no view."));
      return sec;
    }
    const info = el("div", { id: "step-info" });
    const slider = el("input", { type: "range", min: 0, max: steps.length - 1, value: 0, id: "step-slider" });
    const show = (k, recolor) => {
      const s = steps[k];
      const kept = new Set(s.prefiltered && s.prefiltered.length ? s.prefiltered : s.candidates);
      const heldBefore = new Set(data.cameras.filter((c) => c.role === "initial" || (c.role === "chosen" && c.order <= k)).map((c) => c.name));
      const pool = data.cameras.filter((c) => c.train && !heldBefore.has(c.name)).length;
      const order = s.candidates.map((n, i) => [n, s.scores[i]]).sort((a, b) => b[1] - a[1]);
      info.replaceChildren(
        el("p", {}, `Step ${k + 1} of ${steps.length}: ${s.views_before} views held, ${pool} train views not yet held` + (s.prefiltered && s.prefiltered.length ? `, ${s.prefiltered.length} kept by the prefilter` : "") + `, ${s.candidates.length} scored; chose ${s.selected}.`),
        sortableTable([{ title: "rank" }, { title: "candidate" }, { title: "score" }, { title: "kept by the prefilter" }],
          order.slice(0, 12).map(([n, sc], i) => el("tr", { class: n === s.selected ? "chosen-row" : null }, cell(i + 1, 0), el("td", { "data-value": n }, n), el("td", { class: "num", "data-value": sc }, Number.isFinite(sc) ? sc.toPrecision(4) : "n/a"), el("td", {}, kept.has(n) ? "yes" : "no"))), { class: "sortable compact" }),
      );
      if (report.viewer && recolor) {
        const byName = new Map(order.map(([n, sc], i) => [n, i]));
        const colors = data.cameras.map((c) => {
          if (c.name === s.selected) return 0xff2bd6;
          if (byName.has(c.name)) {
            const u = 1 - byName.get(c.name) / Math.max(1, order.length - 1); // 1 = best
            return scoreColor(u);
          }
          return c.role === "test" || c.role === "initial" || (c.role === "chosen" && c.order <= k) ? null : 0x444444;
        });
        report.viewer.setCameraColors(colors);
      }
    };
    slider.addEventListener("input", () => show(Number(slider.value), true));
    const roles = el("button", { type: "button", id: "show-roles" }, "colour the cameras by role again");
    roles.addEventListener("click", () => report.viewer && report.viewer.setCameraColors(null));
    sec.append(el("p", { class: "muted" }, "Move the slider through the steps: in the 3D view the candidates are coloured by their rank (yellow best, blue worst), the chosen view magenta, views not scored dark grey."), slider, " ", roles, info);
    show(0, false);
    return sec;
  }
  function scoreColor(u) {
    // blue (worst) to yellow (best)
    const a = [49, 54, 149], b = [254, 224, 60];
    const c = a.map((x, i) => Math.round(x + (b[i] - x) * u));
    return (c[0] << 16) | (c[1] << 8) | c[2];
  }

  function kvTable(obj, id) {
    return el("table", { class: "kv", id }, el("tbody", {}, Object.entries(obj).map(([k, v]) => el("tr", {}, el("th", {}, k), el("td", { "data-value": typeof v === "number" ? v : null }, typeof v === "number" ? (Number.isInteger(v) ? String(v) : fmt(v, 3)) : v == null ? "n/a" : typeof v === "object" ? JSON.stringify(v) : String(v))))));
  }

  function runDetails() {
    const r = data.results;
    const d = data.dataset || {};
    const wrap = el("div", { class: "details" });
    wrap.append(el("div", {}, el("h3", {}, "Time per stage (s)"), kvTable(r.seconds, "timings")));
    wrap.append(el("div", {}, el("h3", {}, "Options"), kvTable(Object.assign({ method: r.method, preset: r.preset, seed: r.seed, iterations: r.iterations, threads: r.threads }, r.options), "options")));
    const ds = { path: d.path, read: d.loaded ? "yes" : "no" };
    if (d.loaded) Object.assign(ds, { views: d.views, "train views": d.train, "test views": d.test, "frame centre": JSON.stringify(d.frame.center), "frame scale": d.frame.scale, background: d.background ? JSON.stringify(d.background) : "none", "background from": d.background_from });
    wrap.append(el("div", {}, el("h3", {}, "Dataset"), kvTable(ds, "dataset")));
    const sec = section("details", "Timings, options, dataset", wrap);
    sec.append(el("h3", {}, "Warnings"), el("p", { class: "muted" }, `From ${data.warnings_from}.`),
      data.warnings.length ? el("ul", { id: "warnings" }, data.warnings.map((w) => el("li", {}, w))) : el("p", { class: "muted" }, "None."));
    return sec;
  }

  try {
    if (data.kind === "run") runPage();
    else if (data.kind === "grid") gridPage();
    else app.append(el("p", { class: "missing" }, `Unknown report kind: ${data.kind}`));
  } catch (e) {
    app.append(el("p", { class: "missing" }, `This report could not be drawn: ${e && e.message ? e.message : e}`));
    throw e;
  }
  if (!report.ready) report.ready = Promise.resolve(null);

  // ---- the grid page -----------------------------------------------------------------
  function gridPage() {
    document.title = `saresgs report: ${data.title}`;
    const finished = data.jobs.filter((j) => j.status === "finished").length;
    app.append(el("header", {}, el("h1", {}, data.title), el("p", { class: "muted" }, `${data.jobs.length} jobs, ${finished} finished; folder ${data.grid_dir}`)));
    if (data.problems.length) app.append(el("div", { class: "missing", id: "missing" }, el("strong", {}, "Could not read:"), el("ul", {}, data.problems.map((m) => el("li", {}, m)))));

    // per scene: each method's mean PSNR against views held
    const curves = section("curves", "PSNR against views held, per scene (mean over seeds, progress test views)");
    const scenes = Object.keys(data.curves);
    if (!scenes.length) curves.append(el("p", { class: "muted" }, "No finished active job."));
    const grid = el("div", { class: "chart-grid" });
    // one colour per method across every scene
    const allMethods = Array.from(new Set(scenes.flatMap((s) => Object.keys(data.curves[s])))).sort();
    for (const scene of scenes) {
      const methods = Object.keys(data.curves[scene]);
      const series = methods.map((m) => ({ name: m, points: data.curves[scene][m].map((p) => [p[0], p[1]]), cls: `series${allMethods.indexOf(m) % 6}` }));
      grid.append(el("div", { class: "scene-curve", "data-scene": scene }, el("h3", {}, scene), lineChart(series, { xLabel: "views held", yLabel: "PSNR (dB)", label: `PSNR against views on ${scene}` })));
    }
    curves.append(grid);
    app.append(curves);

    const tables = section("tables", "Tables");
    for (const f of data.tables) {
      const box = el("div", { class: "md-file", "data-file": f.file }, el("h3", { class: "file" }, f.file));
      for (const b of f.blocks) {
        if (b.heading != null) box.append(el(b.level <= 2 ? "h3" : "h4", {}, b.heading));
        else if (b.text != null) box.append(el("p", { class: "muted" }, b.text.replace(/\*\*/g, "").replace(/`/g, "")));
        else if (b.table) {
          const [head, ...rows] = b.table;
          const cols = head.map((h) => ({ title: h }));
          const trs = rows.map((r) => el("tr", {}, r.map((c) => {
            const n = Number(c);
            return el("td", { "data-value": c !== "" && Number.isFinite(n) ? n : c, class: c !== "" && Number.isFinite(n) ? "num" : null }, c);
          })));
          box.append(sortableTable(cols, trs, { class: "sortable md-table" }));
        }
      }
      tables.append(box);
    }
    if (!data.tables.length) tables.append(el("p", { class: "muted" }, "The grid wrote no table yet (saresgs ablate writes them when its jobs finish)."));
    app.append(tables);

    const cols = [{ title: "job" }, { title: "scene" }, { title: "method" }, { title: "variant" }, { title: "seed" }, { title: "status" }, { title: "final fit PSNR" }, { title: "in-loop PSNR" }, { title: "views" }, { title: "seconds" }];
    const rows = data.jobs.map((j) =>
      el("tr", { "data-job": j.name },
        el("td", { "data-value": j.name }, j.link ? el("a", { href: j.link }, j.name) : j.name),
        el("td", {}, j.scene), el("td", {}, j.method), el("td", {}, j.variant || ""), el("td", {}, j.seed || ""), el("td", {}, j.status),
        cell(j.final_psnr, 2), cell(j.psnr, 2), cell(j.views, 0), cell(j.seconds, 0)));
    app.append(section("jobs", "Every job", el("p", { class: "muted" }, "Each job's name links to its run report (or, where it has none, its results.json; `saresgs report GRID_DIR --run-reports` writes them)."), sortableTable(cols, rows, { id: "jobs-table" })));

    if (data.plots.length)
      app.append(section("plots", "The grid's plots", el("div", { class: "plots" }, data.plots.map((p) => el("figure", {}, el("img", { src: p.src, alt: p.name }), el("figcaption", {}, p.name))))));
  }
})();
