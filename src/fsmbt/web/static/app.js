// fsmbt web page: calls the JSON API only (docs/web.md); every figure shown comes from it.
"use strict";

const $ = (id) => document.getElementById(id);
const state = { source: null, convert: null, verify: null };

function el(tag, attrs = {}, text) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (text !== undefined) node.textContent = text;
  return node;
}

async function api(path, body) {
  const init = body === undefined ? {} : {
    method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(body) };
  const response = await fetch(path, init);
  const type = response.headers.get("content-type") || "";
  if (!response.ok) {
    const data = type.includes("json") ? await response.json() : { error: response.statusText };
    const err = new Error(data.error || response.statusText);
    err.where = data.where;
    throw err;
  }
  return type.includes("json") ? response.json() : response.blob();
}

function whereText(where) {
  if (!where) return "";
  if (typeof where === "string") return where;
  const parts = [];
  if (where.line) parts.push(`line ${where.line}` + (where.column ? `, column ${where.column}` : ""));
  if (where.element) parts.push(where.element);
  return parts.join(": ");
}

function showError(box, err) {
  box.textContent = "";
  if (!err) return;
  box.append(el("strong", {}, "Error: "), document.createTextNode(err.message));
  const where = whereText(err.where);
  if (where) box.append(el("div", { class: "where" }, where));
}

// -- input: paste, upload, drop, example, format, validation messages -------------------
let inspectTimer = null;
let sourceName = "";

function setSource(text, name) {
  $("source-text").value = text;
  sourceName = name || "";
  $("source-name").textContent = name ? `file: ${name}` : "";
  inspectSoon(0);
}

function sourceRequest() {
  const body = { text: $("source-text").value };
  if (sourceName) body.filename = sourceName;
  if ($("format").value) body.format = $("format").value;
  return body;
}

function inspectSoon(delay = 400) {
  clearTimeout(inspectTimer);
  inspectTimer = setTimeout(inspect, delay);
}

function selectLine(area, line) {
  const lines = area.value.split("\n");
  let start = 0;
  for (let i = 0; i < line - 1 && i < lines.length; i++) start += lines[i].length + 1;
  area.focus();
  area.setSelectionRange(start, start + (lines[line - 1] || "").length);
  const lineHeight = parseFloat(getComputedStyle(area).lineHeight) || 16;
  area.scrollTop = Math.max(0, (line - 3) * lineHeight);
}

function issueItem(severity, message, where) {
  const item = el("li", { class: severity });
  if (where && where.line) {
    const link = el("a", { href: "#", class: "line", "data-line": where.line }, `line ${where.line}`);
    link.addEventListener("click", (e) => { e.preventDefault(); selectLine($("source-text"), where.line); });
    item.append(link, document.createTextNode(" "));
  }
  item.append(el("span", { class: "sev" }, severity + ": "), document.createTextNode(message));
  if (where && where.element) item.append(el("span", { class: "muted" }, ` (${where.element})`));
  return item;
}

async function inspect() {
  const list = $("issues");
  const text = $("source-text").value;
  list.textContent = "";
  $("detected").textContent = "";
  if (!text.trim()) { list.append(el("li", { class: "muted" }, "nothing read yet")); return; }
  try {
    const data = await api("/api/inspect", sourceRequest());
    $("detected").textContent = `read as ${data.format} (${data.kind.toUpperCase()})`;
    for (const issue of data.issues) list.append(issueItem(issue.severity, issue.message, issue));
    for (const warning of data.warnings) list.append(issueItem("warning", warning, null));
    if (!list.children.length) list.append(el("li", { class: "ok" }, "valid model, no warnings"));
  } catch (err) {
    list.append(issueItem("error", err.message, err.where));
  }
}

async function readFile(file) { return { text: await file.text(), name: file.name }; }

function setupInput() {
  $("source-text").addEventListener("input", () => inspectSoon());
  $("format").addEventListener("change", () => inspectSoon(0));
  $("source-file").addEventListener("change", async (e) => {
    const file = e.target.files[0];
    if (file) { const f = await readFile(file); setSource(f.text, f.name); }
  });
  const area = $("source-text");
  area.addEventListener("dragover", (e) => { e.preventDefault(); area.classList.add("drop"); });
  area.addEventListener("dragleave", () => area.classList.remove("drop"));
  area.addEventListener("drop", async (e) => {
    e.preventDefault();
    area.classList.remove("drop");
    const file = e.dataTransfer.files[0];
    if (file) { const f = await readFile(file); setSource(f.text, f.name); }
  });
  $("example").addEventListener("change", async (e) => {
    if (!e.target.value) return;
    const data = await api(`/api/examples/${encodeURIComponent(e.target.value)}`);
    setSource(data.text, data.name);
  });
}

async function loadChoices() {
  const [formats, engines, examples] = await Promise.all(
    [api("/api/formats"), api("/api/engines"), api("/api/examples")]);
  for (const f of formats.filter((f) => f.read)) $("format").append(el("option", { value: f.name }, f.name));
  for (const name of engines.engines) $("engine").append(el("option", { value: name }, name));
  for (const name of engines.hierarchies) $("hierarchy").append(el("option", { value: name }, name));
  for (const name of engines.styles || []) $("style").append(el("option", { value: name }, name));
  for (const ex of examples) $("example").append(el("option", { value: ex.name }, `${ex.name} (${ex.format})`));
}

// -- results: pictures, verdict, properties, metrics, warnings, downloads, stepper -------
function mountSvg(box, svgText, error) {
  if (box.panZoom) { try { box.panZoom.destroy(); } catch (_) { /* already gone */ } box.panZoom = null; }
  box.textContent = "";
  if (!svgText) { box.append(el("div", { class: "error" }, error || "no picture")); return null; }
  box.innerHTML = svgText;
  for (const fold of box.querySelectorAll(".fold")) {  // a fold box: say what a click does
    const title = fold.querySelector("title");
    if (title) title.textContent = fold.id.startsWith("fold@") ? "click: draw this subtree" : "click: draw this composite state";
  }
  const svg = box.querySelector("svg");
  svg.removeAttribute("width");
  svg.removeAttribute("height");
  svg.setAttribute("width", "100%");
  svg.setAttribute("height", "100%");
  if (window.svgPanZoom) {
    box.panZoom = window.svgPanZoom(svg, { controlIconsEnabled: true, zoomScaleSensitivity: 0.3, minZoom: 0.2, maxZoom: 20 });
    return box.panZoom;
  }
  return null;
}

// -- folds: a click on a folded subtree ([k nodes], id fold@PATH) or a closed composite state
// (class fold, id s@PATH) draws it alone (POST /api/picture, docs/web.md 'Big models'); the
// breadcrumb above the picture goes back. Each level's picture is kept, so going back draws
// nothing again; the server caches each opened picture by its request (model and path).
function setupFolds(box, crumbs, model, svgText, error) {
  const levels = [{ label: "whole model", svg: svgText, error }];
  function draw() {
    const level = levels[levels.length - 1];
    mountSvg(box, level.svg, level.error);
    crumbs.textContent = "";
    crumbs.hidden = levels.length === 1 && !box.querySelector(".fold");
    levels.forEach((entry, i) => {
      if (i) crumbs.append(document.createTextNode(" › "));
      const last = i === levels.length - 1;
      const crumb = el(last ? "span" : "a", last ? { class: "crumb current" } : { href: "#", class: "crumb", "data-level": i }, entry.label);
      if (!last) crumb.addEventListener("click", (e) => { e.preventDefault(); levels.length = i + 1; draw(); });
      crumbs.append(crumb);
    });
    if (levels.length === 1 && box.querySelector(".fold")) crumbs.append(el("span", { class: "muted" }, "  (click a dashed box to open it)"));
    box.dataset.level = String(levels.length - 1);
    box.dispatchEvent(new Event("fsmbt:redrawn"));
  }
  box.addEventListener("click", async (e) => {
    const fold = e.target.closest && e.target.closest(".fold");
    if (!fold || !box.contains(fold)) return;
    const isTree = fold.id.startsWith("fold@");
    const path = isTree ? fold.id.slice("fold@".length) : fold.id.slice("s@".length);
    const body = Object.assign({}, model, isTree ? { focus: path } : { composite: path });
    box.classList.add("loading");
    try {
      const data = await api("/api/picture", body);
      levels.push({ label: isTree ? (path === "root" ? "root" : path) : path, svg: data.svg, error: data.error });
      draw();
    } catch (err) {
      crumbs.hidden = false;
      crumbs.append(el("span", { class: "error" }, ` ${err.message}`));
    } finally { box.classList.remove("loading"); }
  });
  draw();
}

function role(root, name) { return root.querySelector(`[data-role="${name}"]`); }

// [key, label, the model kind it applies to (both when absent)]
const METRIC_ROWS = [["graphical", "graphical elements"], ["active", "active elements"], ["depth", "depth"],
  ["states", "states", "fsm"], ["transitions", "transitions", "fsm"], ["sub_fsms", "sub-FSMs", "fsm"],
  ["nodes", "nodes", "bt"], ["leaves", "leaves", "bt"]];

function fillTables(root, data, leftMetrics, rightMetrics) {
  const props = role(root, "properties");
  for (const p of data.properties) {
    const row = el("tr", { class: p.holds ? "holds" : "fails", "data-property": p.name });
    row.append(el("td", {}, p.name.replaceAll("_", " ")), el("td", {}, p.holds ? "✓ holds" : "✗ fails"), el("td", {}, p.detail));
    props.append(row);
  }
  const metrics = role(root, "metrics");
  const cell = (m, key, kind) => (kind && m.kind !== kind ? "—" : String(m[key] ?? ""));
  for (const [key, label, kind] of METRIC_ROWS) {
    if (kind && leftMetrics.kind !== kind && rightMetrics.kind !== kind) continue;
    const row = el("tr", { "data-metric": key });
    row.append(el("td", {}, label), el("td", {}, cell(leftMetrics, key, kind)), el("td", {}, cell(rightMetrics, key, kind)));
    metrics.append(row);
  }
  const warnings = role(root, "warnings");
  for (const w of data.warnings) warnings.append(el("li", {}, w));
  if (!data.warnings.length) role(root, "warnings-box").hidden = true;
}

function setupStepper(root, ce, left, right, leftSvg, rightSvg) {
  const box = role(root, "stepper");
  if (!ce || !ce.steps.length) { box.hidden = true; return; }
  box.hidden = false;
  role(root, "ce-title").textContent = `(${ce.property.replaceAll("_", " ")}: ${ce.detail})`;
  const body = role(root, "steps");
  const side = (step, which) => which === "source"
    ? { state: step.source_state, out: step.source_outputs, anchors: step.source_anchors, status: step.source_status }
    : { state: step.result_state, out: step.result_outputs, anchors: step.result_anchors, status: step.result_status };
  const rows = ce.steps.map((step, i) => {
    const l = side(step, left), r = side(step, right);
    const row = el("tr", { "data-step": i });
    row.append(el("td", {}, String(step.step)), el("td", {}, step.input ?? "(start)"),
      el("td", {}, l.state), el("td", {}, l.out.join(", ") || "—"),
      el("td", {}, r.state), el("td", {}, r.out.join(", ") || "—"), el("td", {}, step.note));
    row.addEventListener("click", () => show(i));
    body.append(row);
    return row;
  });
  let current = 0;
  // The element of a step's anchor, or, for a BT node hidden in a fold of a big tree (docs/web.md
  // 'Big models'), its nearest drawn ancestor - the folded node - found by dropping the last
  // step of its path (n@0/4/2 -> n@0/4 -> n@0 -> n@root; n@T@1/0 -> ... -> n@T@root).
  function drawnElement(svgBox, id) {
    let candidate = id;
    for (;;) {
      const node = svgBox.querySelector(`[id="${CSS.escape(candidate)}"]`);
      if (node) return node;
      const parent = /^(n@(?:[^@/]*@)?)(.+)\/[^/]+$/.exec(candidate);
      if (parent) { candidate = parent[1] + parent[2]; continue; }
      const top = /^(n@(?:[^@/]*@)?)([^/@]+)$/.exec(candidate);
      if (top && top[2] !== "root") { candidate = top[1] + "root"; continue; }
      return null;
    }
  }
  function mark(svgBox, anchors, cls) {
    for (const node of svgBox.querySelectorAll(`.${cls}`)) node.classList.remove(cls);
    for (const id of anchors) {
      const node = drawnElement(svgBox, id);
      if (node) node.classList.add(cls);
    }
  }
  function show(i) {
    current = Math.max(0, Math.min(ce.steps.length - 1, i));
    const step = ce.steps[current];
    const l = side(step, left), r = side(step, right);
    mark(leftSvg, l.anchors, "hl");
    mark(rightSvg, r.anchors, "hl");
    const differs = step.note ? " differs" : "";
    role(root, "left-out").className = "outputs" + differs;
    role(root, "right-out").className = "outputs" + differs;
    role(root, "left-out").textContent = `step ${step.step}: in ${l.state} (${l.status}); output: ${l.out.join(", ") || "nothing"}`;
    role(root, "right-out").textContent = `step ${step.step}: in ${r.state} (${r.status}); output: ${r.out.join(", ") || "nothing"}`;
    rows.forEach((row, k) => row.classList.toggle("current", k === current));
    role(root, "position").textContent = `step ${current + 1} of ${ce.steps.length}` + (step.input ? ` — input ${step.input}` : " — start");
    role(root, "prev").disabled = current === 0;
    role(root, "first").disabled = current === 0;
    role(root, "next").disabled = current === ce.steps.length - 1;
    role(root, "last").disabled = current === ce.steps.length - 1;
    box.dataset.current = String(current);
  }
  role(root, "first").addEventListener("click", () => show(0));
  role(root, "prev").addEventListener("click", () => show(current - 1));
  role(root, "next").addEventListener("click", () => show(current + 1));
  role(root, "last").addEventListener("click", () => show(ce.steps.length - 1));
  for (const svgBox of [leftSvg, rightSvg]) svgBox.addEventListener("fsmbt:redrawn", () => show(current));
  show(0);
}

function saveBlob(blob, name) {
  const url = URL.createObjectURL(blob);
  const link = el("a", { href: url, download: name });
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

function fillDownloads(root, data) {
  role(root, "downloads-box").hidden = false;
  role(root, "result-text").textContent = data.result.text;
  const stem = (sourceName || "model").replace(/\.[^.]*$/, "") + "_converted";
  const box = role(root, "downloads");
  for (const fmt of data.downloads) {
    const label = { btcpp: "BT.CPP XML", scxml: "SCXML", json: "JSON", yaml: "YAML", mermaid: "Mermaid", dot: "DOT", svg: "SVG", png: "PNG", "paper-xml": "paper XML", "paper-text": "paper text", csv: "CSV", md: "Markdown", smach: "SMACH (Python)" }[fmt] || fmt;
    const button = el("button", { type: "button", "data-format": fmt, class: "download", title: `the result as ${fmt}` }, label);
    button.addEventListener("click", async () => {
      try {
        const blob = await api("/api/export", { text: data.result.text, format: data.result.format, to: fmt, name: stem });
        const ext = { btcpp: ".xml", scxml: ".scxml", json: ".json", yaml: ".yaml", mermaid: ".mmd", dot: ".dot", svg: ".svg", png: ".png", "paper-xml": ".fsm.xml", csv: ".csv", md: ".md", "paper-text": ".txt" }[fmt] || ".txt";
        saveBlob(blob, stem + ext);
      } catch (err) { showError($("convert-error"), err); }
    });
    box.append(button);
  }
  const runtimes = role(root, "runtimes");
  for (const kind of data.runtimes) {
    runtimes.append(el("a", { href: `/api/runtime/${kind}`, class: "download runtime", "data-runtime": kind, download: "" }, `${kind === "cpp" ? "C++" : "Python"} runtime (zip)`));
  }
}

function render(container, data, left, right) {
  container.textContent = "";
  container.append($("results-template").content.cloneNode(true));
  container.hidden = false;
  const verdict = role(container, "verdict");
  verdict.textContent = data.verdict + (data.direction ? `  (${data.direction}, engine ${data.engine})` : data.pairing ? `  (${data.pairing})` : "");
  verdict.className = "verdict " + (data.equivalent ? "eq" : data.equivalent === false ? "neq" : "nv");
  verdict.id = container.id + "-verdict";
  return container;
}

async function convert() {
  const box = $("convert-results");
  showError($("convert-error"), null);
  $("convert").disabled = true;
  $("convert").textContent = "Converting…";
  try {
    const sourceModel = sourceRequest();  // what a fold of the source picture is drawn from
    const body = sourceRequest();
    body.engine = $("engine").value || "rules";
    body.options = { loop: $("loop").checked, hierarchy: $("hierarchy").value || "subtrees", style: $("style").value || "auto" };
    const data = await api("/api/convert", body);
    state.convert = data;
    render(box, data);
    role(box, "left-title").textContent = `source (${data.source.format})`;
    role(box, "right-title").textContent = `result (${data.result.format})`;
    const leftBox = role(box, "left"), rightBox = role(box, "right");
    leftBox.id = "svg-source"; rightBox.id = "svg-result";
    setupFolds(leftBox, role(box, "left-crumbs"), sourceModel, data.svg.source, data.svg_errors.source);
    setupFolds(rightBox, role(box, "right-crumbs"), { text: data.result.text, format: data.result.format },
      data.svg.result, data.svg_errors.result);
    fillTables(box, data, data.metrics.source, data.metrics.result);
    fillDownloads(box, data);
    setupStepper(box, data.counterexample, "source", "result", leftBox, rightBox);
  } catch (err) {
    box.hidden = true;
    showError($("convert-error"), err);
  } finally {
    $("convert").disabled = false;
    $("convert").textContent = "Convert";
  }
}

// -- verify two models -----------------------------------------------------------------
const pair = { first: "", second: "" };

function setupVerify() {
  for (const side of ["first", "second"]) {
    $(`${side}-file`).addEventListener("change", async (e) => {
      const file = e.target.files[0];
      if (file) { const f = await readFile(file); $(`${side}-text`).value = f.text; pair[side] = f.name; }
    });
  }
}

async function verify() {
  const box = $("verify-results");
  showError($("verify-error"), null);
  $("verify").disabled = true;
  try {
    const model = (side) => ({ text: $(`${side}-text`).value, filename: pair[side] || undefined });
    const data = await api("/api/verify", { first: model("first"), second: model("second"), options: { loop: $("verify-loop").checked } });
    state.verify = data;
    render(box, data);
    role(box, "left-title").textContent = `first (${data.formats.first})${data.source_side === "first" ? " — source of the check" : ""}`;
    role(box, "right-title").textContent = `second (${data.formats.second})${data.source_side === "second" ? " — source of the check" : ""}`;
    const leftBox = role(box, "left"), rightBox = role(box, "right");
    leftBox.id = "svg-first"; rightBox.id = "svg-second";
    setupFolds(leftBox, role(box, "left-crumbs"), model("first"), data.svg.first, data.svg_errors.first);
    setupFolds(rightBox, role(box, "right-crumbs"), model("second"), data.svg.second, data.svg_errors.second);
    role(box, "m-left").textContent = "first"; role(box, "m-right").textContent = "second";
    fillTables(box, data, data.metrics.first, data.metrics.second);
    const [left, right] = data.source_side === "first" ? ["source", "result"] : ["result", "source"];
    setupStepper(box, data.counterexample, left, right, leftBox, rightBox);
  } catch (err) {
    box.hidden = true;
    showError($("verify-error"), err);
  } finally {
    $("verify").disabled = false;
  }
}

// -- reports (read-only) ---------------------------------------------------------------
async function loadReports() {
  const data = await api("/api/reports");
  const reports = $("report-list"), batches = $("batch-list");
  reports.textContent = ""; batches.textContent = "";
  for (const path of data.reports) {
    const item = el("li");
    item.append(el("a", { href: `/reports/${path.split("/").map(encodeURIComponent).join("/")}`, target: "_blank" }, path));
    reports.append(item);
  }
  for (const path of data.batches) {
    const link = el("a", { href: "#" }, path);
    link.addEventListener("click", async (e) => { e.preventDefault(); showStore(await api(`/api/batch/${path.split("/").map(encodeURIComponent).join("/")}`)); });
    const item = el("li"); item.append(link); batches.append(item);
  }
  if (!data.reports.length) reports.append(el("li", { class: "muted" }, "none"));
  if (!data.batches.length) batches.append(el("li", { class: "muted" }, "none"));
}

function showStore(data) {
  const view = $("batch-view");
  view.textContent = "";
  for (const [name, table] of Object.entries(data.tables)) {
    view.append(el("h4", {}, name));
    const t = el("table", { class: "store" });
    const head = el("tr");
    for (const c of table.columns) head.append(el("th", {}, c));
    t.append(head);
    for (const row of table.rows) {
      const tr = el("tr");
      for (const v of row) tr.append(el("td", {}, v === null ? "" : String(v)));
      t.append(tr);
    }
    view.append(t);
  }
}

// -- tabs ------------------------------------------------------------------------------
function setupTabs() {
  for (const tab of document.querySelectorAll(".tab")) {
    tab.addEventListener("click", () => {
      for (const other of document.querySelectorAll(".tab")) other.classList.toggle("active", other === tab);
      for (const panel of document.querySelectorAll(".panel")) panel.hidden = panel.id !== `panel-${tab.dataset.tab}`;
      if (tab.dataset.tab === "reports") loadReports();
    });
  }
}

document.addEventListener("DOMContentLoaded", async () => {
  setupTabs();
  setupInput();
  setupVerify();
  $("convert").addEventListener("click", convert);
  $("verify").addEventListener("click", verify);
  try {
    await loadChoices();
    // ?example=NAME opens the page on that example and converts it on arrival (README: one
    // command to start on one; the answer usually comes from the server's cache)
    const wanted = new URLSearchParams(location.search).get("example");
    if (wanted) {
      const data = await api(`/api/examples/${encodeURIComponent(wanted)}`);
      $("example").value = wanted;
      setSource(data.text, data.name);
      await convert();
    }
  } catch (err) { showError($("convert-error"), err); }
  document.body.dataset.ready = "1";
});
