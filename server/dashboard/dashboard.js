// The penumbra dashboard: lists jobs, follows the selected one live, submits dropped scenes.
// Every request carries the token in an Authorization header (kept in sessionStorage, never in
// a URL): images and downloads are fetched as blobs for that reason, and the event stream is
// read through fetch, since EventSource cannot send headers.
"use strict";

const TOKEN_KEY = "penumbra-token";
const FINAL = new Set(["succeeded", "failed", "cancelled"]);
const state = {
  jobs: new Map(),        // id -> last record
  thumbs: new Map(),      // id -> {url, key}: object URLs of thumbnails, key = what they show
  selected: null,         // id of the job in the detail panel
  follow: null,           // AbortController of the selected job's event stream
  detailKey: "",          // what the detail image shows
};

const $ = (id) => document.getElementById(id);

function token() { return sessionStorage.getItem(TOKEN_KEY) || ""; }

async function api(path, options = {}) {
  const headers = new Headers(options.headers || {});
  if (token()) headers.set("Authorization", "Bearer " + token());
  if (!headers.has("Accept")) headers.set("Accept", "application/json");
  const response = await fetch(path, { ...options, headers, cache: "no-store" });
  if (!response.ok) throw await problem(response);
  return response;
}

// The server's problem+json as an Error whose message names each field at fault.
async function problem(response) {
  let text = `HTTP ${response.status}`;
  try {
    const p = await response.json();
    text += p.title ? ` ${p.title}` : "";
    text += p.detail ? `: ${p.detail}` : "";
    for (const e of p.errors || []) text += `\n  ${e.pointer || "(document)"}: ${e.detail}`;
  } catch (_) { /* not JSON */ }
  const error = new Error(text);
  error.status = response.status;
  return error;
}

function say(text, kind = "") {
  const m = $("message");
  m.textContent = text;
  m.className = kind;
}

function authFailed(error) {
  if (error.status === 401) {
    $("server-state").textContent = "token needed";
    return true;
  }
  return false;
}

function fmtEta(job) {
  const eta = job.eta_seconds;
  if (job.state !== "running" || typeof eta !== "number") return "";
  return eta < 90 ? `${Math.round(eta)} s` : `${Math.round(eta / 60)} min`;
}

function fmtTime(t) {  // RFC 3339 from the server
  const d = t ? new Date(t) : null;
  return d && !isNaN(d) ? d.toLocaleTimeString() : "";
}

function created(job) {
  const d = job.created_at ? Date.parse(job.created_at) : 0;
  return isNaN(d) ? 0 : d;
}

async function blobUrl(path, accept) {
  const response = await api(path, { headers: { Accept: accept } });
  return URL.createObjectURL(await response.blob());
}

// The image a job shows now: its PNG when done, its progressive preview while it runs.
function imagePath(job) {
  if (job.state === "succeeded") return `/v1/jobs/${job.id}/result?format=png`;
  if (job.state === "running") return `/v1/jobs/${job.id}/result?preview=true&format=png`;
  return null;
}

// A key that changes when the image would: the state and the samples done.
function imageKey(job) {
  return `${job.state}:${job.samples_done || 0}`;
}

async function refreshThumb(job, img) {
  const path = imagePath(job);
  if (!path) return;
  const key = imageKey(job);
  const have = state.thumbs.get(job.id);
  if (have && (have.key === key || (job.state === "running" && Date.now() - have.at < 2000))) {
    img.src = have.url;
    return;
  }
  try {
    const url = await blobUrl(path, "image/png");
    if (have) URL.revokeObjectURL(have.url);
    state.thumbs.set(job.id, { url, key, at: Date.now() });
    img.src = url;
  } catch (_) { /* a preview may not exist yet */ }
}

function button(label, handler, title = "") {
  const b = document.createElement("button");
  b.type = "button";
  b.textContent = label;
  if (title) b.title = title;
  b.addEventListener("click", (e) => { e.stopPropagation(); handler(); });
  return b;
}

function actionsFor(job) {
  const out = [];
  if (job.state === "queued" || job.state === "running") {
    out.push(button("Cancel", () => cancel(job.id)));
  }
  if (job.state === "succeeded") {
    out.push(button("PNG", () => download(job.id, "png")));
    out.push(button("EXR", () => download(job.id, "exr")));
    for (const layer of job.outputs || []) {
      out.push(button(layer, () => download(job.id, "exr", layer), `the ${layer} layer (EXR)`));
    }
  }
  return out;
}

function renderRows() {
  const rows = $("job-rows");
  const jobs = [...state.jobs.values()].sort((a, b) => created(b) - created(a));
  $("empty").hidden = jobs.length > 0;
  const existing = new Map([...rows.children].map((tr) => [tr.dataset.id, tr]));
  let before = rows.firstChild;
  for (const job of jobs) {
    let tr = existing.get(job.id);
    if (!tr) {
      tr = document.createElement("tr");
      tr.dataset.id = job.id;
      tr.innerHTML = '<td><img class="thumb" alt=""></td><td class="id"></td><td class="state"></td>' +
        '<td><progress max="1" value="0"></progress></td><td class="eta"></td><td class="size"></td>' +
        '<td class="when"></td><td class="act"></td>';
      tr.addEventListener("click", () => select(job.id));
    }
    existing.delete(job.id);
    if (tr !== before) rows.insertBefore(tr, before);
    before = tr.nextSibling;
    const cells = tr.children;
    cells[1].textContent = job.id.slice(0, 10);
    cells[1].title = job.id;
    cells[2].textContent = job.state;
    cells[2].className = "state " + job.state;
    cells[3].firstChild.value = job.progress || 0;
    cells[4].textContent = fmtEta(job);
    const r = job.render || {};
    cells[5].textContent = r.width ? `${r.width}×${r.height}, ${r.spp} spp` : "";
    cells[6].textContent = fmtTime(job.created_at);
    const key = job.state + (job.outputs || []).join();
    if (cells[7].dataset.key !== key) {
      cells[7].replaceChildren(...actionsFor(job));
      cells[7].dataset.key = key;
    }
    tr.classList.toggle("selected", job.id === state.selected);
    refreshThumb(job, cells[0].firstChild);
  }
  for (const tr of existing.values()) tr.remove();
}

async function refreshList() {
  try {
    const response = await api("/v1/jobs?limit=50");
    const page = await response.json();
    const seen = new Set();
    for (const job of page.jobs) {
      seen.add(job.id);
      state.jobs.set(job.id, job);
    }
    for (const id of [...state.jobs.keys()]) if (!seen.has(id)) state.jobs.delete(id);
    $("server-state").textContent = `${page.jobs.length} job(s)`;
    renderRows();
    const sel = state.selected && state.jobs.get(state.selected);
    if (sel && !state.follow) showDetail(sel);
  } catch (error) {
    if (!authFailed(error)) $("server-state").textContent = "server unreachable";
  }
}

function showDetail(job) {
  $("detail").hidden = false;
  $("detail-title").textContent = job.id;
  $("detail-state").textContent = job.state;
  $("detail-state").className = "state " + job.state;
  $("detail-progress").value = job.progress || 0;
  $("detail-eta").textContent = fmtEta(job);
  const key = job.state + (job.outputs || []).join();
  const actions = $("detail-actions");
  if (actions.dataset.key !== key || actions.dataset.id !== job.id) {
    actions.replaceChildren(...actionsFor(job));
    actions.dataset.key = key;
    actions.dataset.id = job.id;
  }
  updateDetailImage(job);
}

let detailLoading = false;
async function updateDetailImage(job) {
  const path = imagePath(job);
  const key = job.id + ":" + imageKey(job);
  if (!path || key === state.detailKey || detailLoading) return;
  detailLoading = true;
  try {
    const url = await blobUrl(path, "image/png");
    const img = $("detail-image");
    const old = img.src;
    img.src = url;
    img.dataset.key = key;
    state.detailKey = key;
    if (old.startsWith("blob:")) URL.revokeObjectURL(old);
  } catch (_) {
    /* no preview yet */
  } finally {
    detailLoading = false;
  }
}

function select(id) {
  if (state.follow) state.follow.abort();
  state.follow = null;
  state.selected = id;
  state.detailKey = "";
  const img = $("detail-image");
  if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
  img.removeAttribute("src");
  img.dataset.key = "";
  renderRows();
  const job = state.jobs.get(id);
  if (job) showDetail(job);
  if (job && !FINAL.has(job.state)) follow(id);
}

// Follows a job's Server-Sent Events (GET /v1/jobs/{id}/events) through fetch; where the
// server has no stream, the list's polling keeps the panel current.
async function follow(id) {
  const controller = new AbortController();
  state.follow = controller;
  let lastId = null;
  for (let attempt = 0; attempt < 5 && state.follow === controller; ++attempt) {
    try {
      const headers = { Accept: "text/event-stream" };
      if (lastId) headers["Last-Event-ID"] = lastId;
      const response = await api(`/v1/jobs/${id}/events`, { headers, signal: controller.signal });
      if (!(response.headers.get("Content-Type") || "").startsWith("text/event-stream")) break;
      const reader = response.body.getReader();
      const decoder = new TextDecoder();
      let buffer = "";
      for (;;) {
        const { value, done } = await reader.read();
        if (done) break;
        buffer += decoder.decode(value, { stream: true });
        let end;
        while ((end = buffer.search(/\r?\n\r?\n/)) >= 0) {
          const block = buffer.slice(0, end);
          buffer = buffer.slice(end).replace(/^\r?\n\r?\n/, "");
          const data = [];
          for (const line of block.split(/\r?\n/)) {
            if (line.startsWith("data:")) data.push(line.slice(5).replace(/^ /, ""));
            else if (line.startsWith("id:")) lastId = line.slice(3).trim();
          }
          if (!data.length) continue;
          const job = JSON.parse(data.join("\n"));
          state.jobs.set(job.id, job);
          renderRows();
          if (state.selected === job.id) showDetail(job);
          if (FINAL.has(job.state)) {
            if (state.follow === controller) state.follow = null;
            return;
          }
        }
      }
    } catch (error) {
      if (controller.signal.aborted) return;
      if (error.status === 404) break;  // no event stream on this server
    }
  }
  if (state.follow === controller) state.follow = null;
}

async function cancel(id) {
  try {
    await api(`/v1/jobs/${id}`, { method: "DELETE" });
    say(`cancelled ${id}`, "ok");
    refreshList();
  } catch (error) {
    say(error.message, "error");
  }
}

async function download(id, format, layer) {
  try {
    let path = `/v1/jobs/${id}/result?format=${format}`;
    if (layer) path += `&layer=${encodeURIComponent(layer)}`;
    const url = await blobUrl(path, format === "png" ? "image/png" : "image/x-exr");
    const a = document.createElement("a");
    a.href = url;
    a.download = `${id}${layer ? "." + layer : ""}.${format}`;
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 10000);
  } catch (error) {
    say(error.message, "error");
  }
}

async function submitFile(file) {
  const glb = /\.glb$/i.test(file.name);
  const type = glb ? "model/gltf-binary" : "application/json";
  try {
    const body = glb ? await file.arrayBuffer() : await file.text();
    const response = await api("/v1/jobs", { method: "POST", headers: { "Content-Type": type }, body });
    const job = await response.json();
    say(`submitted ${file.name} as ${job.id}`, "ok");
    state.jobs.set(job.id, job);
    select(job.id);
  } catch (error) {
    if (!authFailed(error)) say(`${file.name}: ${error.message}`, "error");
    else say("the server needs a token: enter it above", "error");
  }
}

function setup() {
  $("token").value = token();
  $("token-form").addEventListener("submit", (e) => {
    e.preventDefault();
    sessionStorage.setItem(TOKEN_KEY, $("token").value.trim());
    say("token set for this tab", "ok");
    refreshList();
  });
  const drop = $("drop");
  drop.addEventListener("dragover", (e) => { e.preventDefault(); drop.classList.add("over"); });
  drop.addEventListener("dragleave", () => drop.classList.remove("over"));
  drop.addEventListener("drop", (e) => {
    e.preventDefault();
    drop.classList.remove("over");
    for (const f of e.dataTransfer.files) submitFile(f);
  });
  $("file").addEventListener("change", (e) => {
    for (const f of e.target.files) submitFile(f);
    e.target.value = "";
  });
  refreshList();
  setInterval(refreshList, 1500);
}

document.addEventListener("DOMContentLoaded", setup);
