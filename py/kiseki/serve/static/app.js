// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The route-instruction page (thesis 000, section 2.3): pick start, via and goal waypoints on the
// taught map, start the route, watch the robot live, read the stop error at the goal.

// client.js, not api.js: the server asks a token of every path that starts with /api
import { Api, ApiError, LiveSocket, loadToken, saveToken } from "./client.js";
import { MapView } from "./mapview.js";
import { RoutePicker } from "./route.js";

const $ = (id) => document.getElementById(id);
const fmt = (v, digits = 2) => (Number.isFinite(v) ? v.toFixed(digits) : "-");
const STOP_TOLERANCE_M = 0.1; // the thesis' goal: stop within 0.1 m (section 2.2)

const app = {
  api: new Api(loadToken()),
  view: new MapView($("map"), $("markers")),
  waypoints: [],
  state: { status: "idle", history: [] },
  live: null,
  socket: null,
  latency: null, // {t0, posted} while waiting for the first pose after a click on start
  updates: 0,
  recent: [],
  seq: -1, // the sequence number of the state shown (the server's message count)
  epoch: null, // the server's run: a restarted server counts its messages from 1 again
  starting: null, // {after: the route shown at the click} until the server shows the new one
  startPending: false, // a start request is on its way
  stopAgain: false, // STOP was pressed meanwhile: the start may reach the server after the stop
  drawn: [], // the last states drawn, {seq, epoch, route, status, pose}: what the worker saw
};
const DRAWN_KEPT = 2000;
window.kiseki = app; // for the browser tests and a curious teacher's console

function showMessage(text, kind = "error") {
  const box = $("message");
  box.hidden = !text;
  box.textContent = text || "";
  box.className = `message${kind === "info" ? " info" : ""}`;
}

function handleError(err) {
  if (err instanceof ApiError && err.status === 401) {
    $("token-form").hidden = false;
    showMessage("This server needs its access token.");
    return;
  }
  showMessage(err.message || String(err));
}

// ---- waypoints and the map ----

function normaliseWaypoints(body) {
  const list = Array.isArray(body) ? body : body.waypoints || [];
  return list.map((w) => {
    const pose = w.pose || [w.x, w.y, w.theta];
    return { ...w, name: w.name, x: pose[0], y: pose[1], theta: pose[2] ?? 0 };
  });
}

async function loadWaypoints() {
  const body = await app.api.waypoints();
  app.waypoints = normaliseWaypoints(body);
  app.mapMeta = (body && (body.map || body.map_info)) || app.mapMeta || {};
  picker.setNames(app.waypoints.map((w) => w.name));
  renderRenameList();
}

async function loadMap() {
  const source = await app.api.map();
  app.view.setMap(source, app.mapMeta || {});
  app.view.frame(app.waypoints);
  app.view.resize();
}

function placeMarkers() {
  if (!app.view.view) return;
  app.view.placeMarkers(app.waypoints, (name) => picker.rolesOf(name), (name) => picker.tap(name));
  app.view.draw();
}

// ---- the route being picked ----

const picker = new RoutePicker({
  onChange: () => {
    const check = picker.check(app.waypoints, app.view.map ? app.view : null);
    app.view.route = check.points;
    app.view.blocked = check.blocked;
    $("route-text").textContent = picker.text() || "no route";
    const box = $("route-check");
    box.hidden = !check.messages.length && !check.ok;
    box.className = `check ${check.ok && !check.blocked.length ? "ok" : "bad"}`;
    box.textContent = check.messages.length ? check.messages.join(" ") : "Route looks good.";
    app.routeOk = check.ok;
    updateButtons();
    placeMarkers();
    app.view.draw();
  },
});

function updateButtons() {
  // left enabled while a route runs: the server refuses a second one and the page says why
  $("start-route").disabled = !app.routeOk;
  // the stop button is never disabled: a stale view must not keep anyone from halting the robot
}

async function startRoute() {
  const t0 = performance.now();
  showMessage("");
  // until the server shows the new route the page shows "starting" and no robot: the previous
  // route's status and pose are not this route's (the start may place the robot elsewhere)
  app.starting = { after: app.state.route ? app.state.route.id : null };
  app.startPending = true;
  app.stopAgain = false;
  draw();
  try {
    const body = await app.api.startRoute(picker.route());
    app.latency = { t0, posted: performance.now() - t0, id: body && body.id };
    app.startPending = false;
    if (app.stopAgain) {
      // the two requests travel on two connections and may be taken in either order: a stop
      // taken before this start stopped nothing, so it is sent again now
      app.stopAgain = false;
      await stopRoute();
    } else {
      await refreshState();
    }
  } catch (err) {
    app.startPending = false;
    app.starting = null;
    handleError(err);
    refreshState().catch(() => {});
  }
}

async function stopRoute() {
  if (app.startPending) app.stopAgain = true;
  try {
    await app.api.stop();
    await refreshState();
  } catch (err) {
    handleError(err);
  }
}

// ---- state and the live view ----

const PHASES = { outbound: "to the goal", dwell: "at the goal", return: "going home" };

function legText(state) {
  const leg = state.leg;
  if (leg === null || leg === undefined) return "-";
  if (typeof leg === "string") return leg;
  if (typeof leg === "object") {
    const phase = PHASES[leg.phase] || leg.phase || "";
    if (leg.from == null) return phase || "-";
    return `${leg.from} \u2192 ${leg.to}${phase ? ` (${phase})` : ""}`;
  }
  const names = routeNames(state.route);
  if (Number.isInteger(leg) && names.length > leg + 1) {
    return `${leg + 1}/${names.length - 1}: ${names[leg]} \u2192 ${names[leg + 1]}`;
  }
  return String(leg);
}

function routeNames(route) {
  if (!route) return [];
  return [route.start, ...(route.via || []), route.goal, route.home].filter((n) => n != null);
}

function routeText(route) {
  if (!route) return "-";
  const names = [route.start, ...(route.via || []), route.goal];
  return `${names.join(" \u2192 ")}${route.home ? ` \u21a9 ${route.home}` : ""}`;
}

function stopErrorCell(value) {
  if (!Number.isFinite(value)) return ["-", ""];
  return [`${fmt(value, 3)} m`, value <= STOP_TOLERANCE_M ? "ok" : "bad"];
}

/** "x, y m  theta deg", short enough for a tile. */
function poseText([x, y, theta]) {
  return `${fmt(x)}, ${fmt(y)} m  ${fmt((theta * 180) / Math.PI, 0)}\u00b0`;
}

/** The state as the page shows it: while a start is on its way, no robot and "starting". */
function shownState() {
  const s = app.state;
  if (!app.starting) return s;
  const none = { route: null, leg: null, pose: null, estimate: null, particles: [] };
  return { ...s, ...none, status: "starting" };
}

function renderState() {
  const s = shownState();
  document.body.dataset.status = s.status || "idle";
  document.body.dataset.route = s.route ? String(s.route.id) : "";
  $("status").textContent = s.status === "starting" ? "starting\u2026" : s.status || "idle";
  $("leg").textContent = legText(s);
  $("speed").textContent = Number.isFinite(s.speed) ? `${fmt(s.speed)} m/s` : "-";
  const pose = $("pose");
  pose.dataset.seq = String(app.seq);
  if (Array.isArray(s.pose)) {
    pose.textContent = poseText(s.pose);
    [pose.dataset.x, pose.dataset.y, pose.dataset.theta] = s.pose.map(String);
  } else {
    pose.textContent = "-"; // no robot yet on this route: not the last route's pose
    [pose.dataset.x, pose.dataset.y, pose.dataset.theta] = ["", "", ""];
  }
  const e = s.estimate;
  $("estimate").textContent = Array.isArray(e) ? poseText(e) : "-";
  $("est-error").textContent =
    Array.isArray(e) && Array.isArray(s.pose)
      ? `${fmt(Math.hypot(e[0] - s.pose[0], e[1] - s.pose[1]), 3)} m`
      : "-";
  const [stopText, stopClass] = stopErrorCell(s.stop_error_m);
  const stop = $("stop-error");
  stop.textContent = stopText;
  stop.className = stopClass;
  stop.dataset.m = Number.isFinite(s.stop_error_m) ? String(s.stop_error_m) : "";
  $("dwell").textContent = dwellText(s);
  if (s.status === "running" && s.route) {
    // every page shows the route that runs, whoever started it
    const check = picker.check(app.waypoints, null, s.route);
    app.view.route = check.points;
    app.view.blocked = [];
  }
  renderHistory(s.history || []);
  updateButtons();
}

function dwellText(s) {
  const left = s.dwell_left_s ?? s.dwell_s;
  if (Number.isFinite(left)) return `${fmt(left, 1)} s left (part taken)`;
  if (s.leg && s.leg.phase === "return") return "done";
  return "-";
}

function renderHistory(history) {
  const body = $("history");
  body.replaceChildren();
  $("history-empty").hidden = history.length > 0;
  [...history].reverse().forEach((h, i) => {
    const row = document.createElement("tr");
    const [text, cls] = stopErrorCell(h.stop_error_m);
    const cells = [h.id ?? history.length - i, routeText(h.route || h), h.status || "", text];
    cells.forEach((value, k) => {
      const td = document.createElement("td");
      td.textContent = value;
      if (k === 3 && cls) td.className = cls;
      row.append(td);
    });
    row.dataset.stopError = Number.isFinite(h.stop_error_m) ? String(h.stop_error_m) : "";
    body.append(row);
  });
}

/**
 * Whether a state (a live message or a reply) is not older than the one shown: by its sequence
 * number within the server's epoch. A reply overtaken by a live message (a stop's reply by the
 * "stopped" message), or a message overtaken by a reply, never puts an older state back.
 */
function isCurrent(s) {
  if (s.epoch !== undefined && s.epoch !== app.epoch) return true; // a (re)started server
  return !Number.isInteger(s.seq) || s.seq >= app.seq;
}

/** Takes a current state's numbering; a new route starts its own trail and ends "starting". */
function takeNumbering(s) {
  if (s.epoch !== undefined && s.epoch !== app.epoch) {
    app.epoch = s.epoch;
    app.seq = -1;
  }
  if (Number.isInteger(s.seq)) app.seq = s.seq;
  const shown = app.state.route ? app.state.route.id : null;
  const route = s.route ? s.route.id : null;
  if (route !== shown) app.view.trail = [];
  if (app.starting && route !== null && route !== app.starting.after) app.starting = null;
}

/** Draws the state shown and notes what was drawn. */
function draw() {
  const s = shownState();
  app.view.setLive(s);
  renderState();
  app.drawn.push({
    seq: app.seq,
    epoch: app.epoch,
    route: s.route ? s.route.id : null,
    status: s.status,
    pose: Array.isArray(s.pose) ? [...s.pose] : null,
  });
  if (app.drawn.length > DRAWN_KEPT) app.drawn.shift();
}

async function refreshState() {
  const fresh = await app.api.state();
  if (!isCurrent(fresh)) return;
  takeNumbering(fresh);
  app.state = { history: [], ...fresh };
  draw();
}

/** Live messages merge at once; the page draws at most once per frame. */
function onLive(message) {
  if (!isCurrent(message)) return; // an older message than the state shown
  takeNumbering(message);
  const before = app.state.status;
  app.state = { ...app.state, ...message };
  app.updates += 1;
  if (Number.isInteger(message.seq)) {
    // the last messages by sequence number: pages on one robot can be compared exactly
    app.recent.push({ seq: message.seq, pose: message.pose, leg: message.leg });
    if (app.recent.length > 100) app.recent.shift();
  }
  if (before === "running" && app.state.status !== "running") showEnd(app.state);
  if (!app.frame) app.frame = requestAnimationFrame(drawFrame);
}

function drawFrame() {
  app.frame = 0;
  $("map").dataset.updates = String(app.updates);
  draw();
  const pending = app.latency;
  const shown = shownState();
  if (pending && shown.status === "running" && Array.isArray(shown.pose)) {
    app.latency = null;
    const ms = performance.now() - pending.t0; // the first pose of the route is on the canvas
    app.lastLatency = { click_to_first_pose_ms: ms, click_to_accepted_ms: pending.posted };
    const p = $("latency");
    p.hidden = false;
    p.textContent = `Click to first pose on screen: ${fmt(ms, 0)} ms`;
  }
}

/** A route that ended on its own with a reason (or was stopped) says so once. */
function showEnd(state) {
  if (state.status === "stopped") showMessage(`Route stopped: ${state.detail || "stopped"}.`, "info");
  else if (state.status === "finished") showMessage("");
}

function connect() {
  if (app.socket) app.socket.close();
  app.socket = new LiveSocket(app.api, {
    onMessage: onLive,
    onOpen: () => refreshState().catch(handleError), // a restarted server: a new epoch
    onStatus: (status) => {
      document.body.dataset.connection = status;
      $("connection").textContent = status === "live" ? "live" : "reconnecting\u2026";
    },
  });
  app.socket.open();
}

// ---- renaming ----

function renderRenameList() {
  const list = $("rename-list");
  list.replaceChildren();
  for (const w of app.waypoints) {
    const item = document.createElement("li");
    const input = document.createElement("input");
    input.value = w.name;
    input.setAttribute("aria-label", `new name for ${w.name}`);
    input.dataset.waypoint = w.name;
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = "Rename";
    button.dataset.rename = w.name;
    button.addEventListener("click", () => rename(w.name, input.value.trim()));
    input.addEventListener("keydown", (e) => {
      if (e.key === "Enter") rename(w.name, input.value.trim());
    });
    item.append(input, button);
    list.append(item);
  }
}

async function rename(name, newName) {
  if (!newName || newName === name) return;
  try {
    await app.api.rename(name, newName);
    picker.renamed(name, newName);
    await loadWaypoints();
    placeMarkers();
    showMessage(`Renamed ${name} to ${newName}.`, "info");
  } catch (err) {
    handleError(err);
  }
}

// ---- start-up ----

async function boot() {
  try {
    await loadWaypoints();
    await loadMap();
    picker.changed();
    await refreshState();
    connect();
    $("token-form").hidden = true;
    showMessage("");
  } catch (err) {
    handleError(err);
  }
}

$("token-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const token = $("token-input").value.trim();
  saveToken(token);
  app.api.token = token;
  boot();
});
$("start-route").addEventListener("click", startRoute);
$("stop").addEventListener("click", stopRoute);
$("clear-route").addEventListener("click", () => picker.clear());
window.addEventListener("resize", () => {
  app.view.resize();
  placeMarkers();
});
picker.bind();
boot();
