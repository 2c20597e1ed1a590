// The studio's page: sends the what-ifs, polls the state, swaps in the HTML fragments the
// server draws (the map, the neck, the advice, a note), shows each bad value's message next
// to its control. No HTML is built here: the fragments come from the server's templates.
"use strict";

const $ = (id) => document.getElementById(id);
const shown = { version: -1, map: null, done: -1, status: "", advice: "", dress: "", announced: "", player: "" };
let busy = true;

async function failure(response) {
  try {
    const body = await response.json();
    return body;
  } catch (e) {
    return { error: response.status + " " + response.statusText, errors: {} };
  }
}

// Replaces an element's content with HTML drawn by the server, keeping the focus on the
// control that had it (a note's button keeps its id across refreshes).
function swap(element, html) {
  const focused = document.activeElement && element.contains(document.activeElement) ? document.activeElement.id : null;
  const template = document.createElement("template");
  template.innerHTML = html;
  element.replaceChildren(template.content);
  if (focused && $(focused)) $(focused).focus();
}

async function fragment(element, url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error((await failure(response)).error);
  swap(element, await response.text());
}

function say(element, text) {
  element.replaceChildren(document.createTextNode(text));
}

function paragraph(text, className) {
  const p = document.createElement("p");
  p.textContent = text;
  if (className) p.className = className;
  return p;
}

// The form ----------------------------------------------------------------------------

function controls() {
  const form = $("what-if");
  const values = { relief: form.relief.value, action12: {}, nut: {}, saddle_change: {}, fret: form.fret.value,
                   fret_offset: form.level.checked ? "level" : form.fret_offset.value };
  form.querySelectorAll("input[data-key]").forEach((input) => {
    if (input.value.trim()) values[input.dataset.key][input.dataset.string] = input.value;
  });
  const attacks = Array.from(form.querySelectorAll("input[name=attack]:checked"), (box) => box.value);
  if (form.amplitude.value.trim()) attacks.push(form.amplitude.value.trim());
  values.strengths = attacks.join(",");
  values.player = !form.player.disabled && form.player.checked;
  return values;
}

function clearErrors() {
  document.querySelectorAll("#what-if .error, #error-export, #error-tolerate, #error-calibrate").forEach((span) => say(span, ""));
  document.querySelectorAll("#what-if [aria-invalid]").forEach((input) => input.removeAttribute("aria-invalid"));
}

function showErrors(errors) {
  for (const [field, message] of Object.entries(errors || {})) {
    const span = $("error-" + field) || $("error-form");
    say(span, message);
    const input = $(field) || (field === "strengths" ? $("amplitude") : null);
    if (input) input.setAttribute("aria-invalid", "true");
  }
}

async function post(url, body) {
  return fetch(url, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
}

async function playMap(values) {
  clearErrors();
  const response = await post("/api/what-if", values);
  if (!response.ok) {
    const body = await failure(response);
    showErrors(Object.keys(body.errors || {}).length ? body.errors : { form: body.error });
    return;
  }
  const job = await response.json();
  const superseded = job.superseded.map((j) => (typeof j.id === "number" ? "map " + j.id : j.id) + " (" + j.label + ")");
  say($("error-form"), "");
  if (superseded.length) $("queue-now").append(paragraph("Replaced while waiting: " + superseded.join("; ") + ".", "superseded"));
  wake();
}

$("what-if").addEventListener("submit", (event) => {
  event.preventDefault();
  playMap(controls());
});

$("reset").addEventListener("click", () => {
  const form = $("what-if");
  form.querySelectorAll("input:not([type=checkbox])").forEach((input) => { if (input.id !== "amplitude") input.value = ""; });
  form.level.checked = false;
  playMap(controls());
});

// The state ---------------------------------------------------------------------------

function showQueue(jobs, map) {
  const box = $("queue-now");
  const lines = [];
  if (jobs.running) {
    const r = jobs.running;
    lines.push(paragraph(r.kind === "map" ? "Playing map " + r.id + " (" + r.label + "): " + r.done + " of " + r.total + " notes."
                                          : "Searching: " + r.label + "."));
    $("progress").max = r.total || 1;
    $("progress").value = r.kind === "map" ? r.done : 0;
  } else {
    lines.push(paragraph(map && map.status === "done" ? "Idle: map " + map.id + " is complete." : "Idle."));
    $("progress").max = 1;
    $("progress").value = map && map.status === "done" ? 1 : 0;
  }
  const name = (id) => (typeof id === "number" ? "map " + id : id);
  for (const j of jobs.pending) lines.push(paragraph("Waiting: " + name(j.id) + " (" + j.label + ")."));
  for (const j of jobs.superseded) {
    lines.push(paragraph("Replaced by " + name(j.superseded_by) + " before it started: " + name(j.id) + " (" + j.label + ").",
                         "superseded"));
  }
  box.replaceChildren(...lines);
}

function showSetup(setup) {
  for (const s of setup) {
    $("action12." + s.name).placeholder = s.action12_mm === null ? "" : s.action12_mm.toFixed(2);
    $("nut." + s.name).placeholder = s.nut_gap_mm.toFixed(2);
    $("saddle_change." + s.name).placeholder = "0 (now " + s.saddle_mm.toFixed(2) + ")";
  }
  if (setup.length) $("relief").placeholder = setup[0].relief_mm.toFixed(2);
}

async function refresh() {
  const response = await fetch("/api/state");
  if (!response.ok) throw new Error((await failure(response)).error);
  const state = await response.json();
  say($("connection"), "");
  busy = Boolean(state.jobs.running || state.jobs.pending.length);
  if (state.version === shown.version) return;
  shown.version = state.version;
  showQueue(state.jobs, state.map);
  showSetup(state.setup);
  const map = state.map;
  const player = state.player;
  const playerKey = player.version + ":" + player.status + ":" + player.calibrated_map;
  const reportChanged = playerKey !== shown.player;
  if (reportChanged) {
    // A scale found for the first time: later what-ifs play at the player's touch unless unticked.
    if (player.scale !== null && $("player").disabled) $("player").checked = true;
    $("player").disabled = player.scale === null;
    say($("player-scale"), player.scale === null ? "" : ": \u00d7" + player.scale.toFixed(2));
    await fragment($("player-report"), "/fragment/player");
  }
  if (map && map.status !== "running" && map.status !== "waiting" && shown.announced !== map.id + map.status) {
    shown.announced = map.id + map.status;
    say($("announce"), "Map " + map.id + " " + (map.status === "done" ? "is complete: " + map.summary.buzzing + " of " +
        map.summary.played + " notes buzz, " + map.summary.marginal + " are marginal." : map.status + "."));
  }
  if (map && (reportChanged || map.id !== shown.map || map.done !== shown.done || map.status !== shown.status)) {
    await fragment($("maps"), "/fragment/maps?map=" + map.id);
    // What the fragment shows (it may be newer than this state): no redraw until it changes.
    const drawn = $("map-now");
    shown.done = drawn ? Number(drawn.dataset.done) : map.done;
    shown.status = drawn ? drawn.dataset.status : map.status;
  }
  shown.player = playerKey;
  if (map && map.id !== shown.map) {
    shown.map = map.id;
    await fragment($("neck"), "/fragment/neck?map=" + map.id);
  }
  const advice = (state.done || "") + ":" + state.advice + ":" + state.advice_progress;
  if (advice !== shown.advice) {
    shown.advice = advice;
    await fragment($("advice"), "/fragment/advice");
  }
  const dress = (state.done || "") + ":" + state.dress + ":" + state.dress_progress;
  if (dress !== shown.dress) {
    shown.dress = dress;
    await fragment($("dress-result"), "/fragment/dress");
  }
  $("advise").disabled = !state.done;
  $("dress").disabled = !state.done;
  $("export").disabled = !state.done;
}

let timer = null;
async function poll() {
  timer = null;
  try {
    await refresh();
  } catch (e) {
    say($("connection"), "The studio does not answer (" + e.message + "); retrying.");
  }
  timer = setTimeout(poll, busy ? 300 : 1500);
}

function wake() {
  busy = true;
  if (timer !== null) {
    clearTimeout(timer);
    poll();
  }
}

// A note ------------------------------------------------------------------------------

$("maps").addEventListener("click", async (event) => {
  const button = event.target.closest("button.note");
  if (!button || button.disabled) return;
  document.querySelectorAll("#maps .selected").forEach((b) => b.classList.remove("selected"));
  button.classList.add("selected");
  const query = new URLSearchParams({ map: button.dataset.map, string: button.dataset.string, fret: button.dataset.fret,
                                      strength: button.dataset.strength });
  say($("note"), "Playing " + button.getAttribute("aria-label") + " again for its contacts\u2026");
  try {
    await fragment($("note"), "/fragment/note?" + query);
    const audio = $("note-audio");
    if (audio) audio.play().catch(() => {});
  } catch (e) {
    $("note").replaceChildren(paragraph(e.message, "error"));
  }
});

// The player's report: what a clicked note sounds like on the player's own instrument.
$("note").addEventListener("click", async (event) => {
  const button = event.target.closest("button.heard");
  const note = $("note-now");
  if (!button || !note) return;
  const response = await post("/api/heard", { string: note.dataset.string, fret: Number(note.dataset.fret),
                                              strength: note.dataset.strength, heard: button.dataset.heard });
  if (!response.ok) {
    $("note").append(paragraph((await failure(response)).error, "error"));
    return;
  }
  document.querySelectorAll("#note button.heard").forEach((b) => b.setAttribute("aria-pressed", String(b === button)));
  wake();
});

// A request whose bad values are answered next to their controls (or `where`).
async function ask(url, body, where) {
  clearErrors();
  const response = await post(url, body);
  if (!response.ok) {
    const failed = await failure(response);
    showErrors(Object.keys(failed.errors || {}).some((k) => k !== "form" && $("error-" + k)) ? failed.errors : { [where]: failed.error });
  }
  wake();
}

$("calibrate").addEventListener("click", () => ask("/api/calibrate", { tolerate: $("tolerate").value }, "calibrate"));

// Advice and export -------------------------------------------------------------------

$("advise").addEventListener("click", () => ask("/api/advice", { tolerate: $("tolerate").value }, "tolerate"));

$("dress").addEventListener("click", () => ask("/api/dress", { tolerate: $("tolerate").value }, "tolerate"));

$("export").addEventListener("click", async () => {
  clearErrors();
  const response = await post("/api/export", {});
  if (!response.ok) {
    say($("error-export"), (await failure(response)).error);
    return;
  }
  const report = await response.json();
  const link = document.createElement("a");
  link.href = report.url;
  link.id = "report-link";
  link.textContent = "Open the report";
  $("export-result").replaceChildren(link, document.createTextNode(" (saved as " + report.file + ")"));
});

poll();
