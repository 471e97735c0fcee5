// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The route being picked: taps on the map (the role buttons say what the next tap sets) or lists.

const $ = (id) => document.getElementById(id);
const HINTS = {
  start: "Tap the start waypoint on the map.",
  via: "Tap the via-waypoints in the order the robot passes them, then Goal.",
  goal: "Tap the goal waypoint (the parts shelf).",
  home: "Tap the home waypoint the robot returns to (your cell).",
};

export class RoutePicker {
  constructor({ onChange }) {
    this.onChange = onChange;
    this.names = [];
    this.start = null;
    this.via = [];
    this.goal = null;
    this.home = null;
    this.role = "start";
  }

  bind() {
    for (const button of document.querySelectorAll(".role")) {
      button.addEventListener("click", () => this.setRole(button.dataset.role));
    }
    for (const role of ["start", "goal", "home"]) {
      $(`pick-${role}`).addEventListener("change", (e) => {
        this[role] = e.target.value || null;
        this.changed();
      });
    }
    $("via-add").addEventListener("click", () => {
      const name = $("pick-via").value;
      if (name) this.via.push(name);
      this.changed();
    });
  }

  setRole(role) {
    this.role = role;
    for (const button of document.querySelectorAll(".role")) {
      button.setAttribute("aria-pressed", String(button.dataset.role === role));
    }
    $("role-hint").textContent = HINTS[role] || "Route complete: press Start route.";
  }

  /** A tap on waypoint `name` sets the current role, then moves on to the next one. */
  tap(name) {
    if (this.role === "start") {
      this.start = name;
      if (!this.home) this.home = name; // the worker's cell, by default
      this.setRole("via");
    } else if (this.role === "via") {
      this.via.push(name);
    } else if (this.role === "goal") {
      this.goal = name;
      this.setRole("home");
    } else if (this.role === "home") {
      this.home = name;
      this.setRole(null);
    }
    this.changed();
  }

  clear() {
    this.start = null;
    this.via = [];
    this.goal = null;
    this.home = null;
    this.setRole("start");
    this.changed();
  }

  setNames(names) {
    this.names = names;
    for (const id of ["pick-start", "pick-via", "pick-goal", "pick-home"]) {
      const select = $(id);
      select.replaceChildren(new Option("\u2014", ""), ...names.map((n) => new Option(n, n)));
    }
  }

  renamed(old, name) {
    for (const role of ["start", "goal", "home"]) if (this[role] === old) this[role] = name;
    this.via = this.via.map((v) => (v === old ? name : v));
  }

  route() {
    return { start: this.start, via: [...this.via], goal: this.goal, home: this.home };
  }

  rolesOf(name) {
    const roles = [];
    if (this.start === name) roles.push("start");
    if (this.via.includes(name)) roles.push("via");
    if (this.goal === name) roles.push("goal");
    if (this.home === name) roles.push("home");
    return roles;
  }

  text() {
    if (!this.start && !this.goal && !this.via.length) return "";
    const names = [this.start || "?", ...this.via, this.goal || "?"];
    return `${names.join(" \u2192 ")} \u21a9 ${this.home || "?"}`;
  }

  changed() {
    $("pick-start").value = this.start || "";
    $("pick-goal").value = this.goal || "";
    $("pick-home").value = this.home || "";
    const list = $("via-list");
    list.replaceChildren();
    this.via.forEach((name, i) => {
      const item = document.createElement("li");
      const remove = document.createElement("button");
      remove.type = "button";
      remove.textContent = "\u2715";
      remove.setAttribute("aria-label", `remove via ${name}`);
      remove.addEventListener("click", () => {
        this.via.splice(i, 1);
        this.changed();
      });
      item.append(document.createTextNode(name), remove);
      list.append(item);
    });
    this.onChange();
  }

  /** The names along the route, out and back, as the server plans them (or planned them). */
  static legs(route) {
    if (route.outbound && route.return) return { out: route.outbound, back: route.return };
    const via = route.via || [];
    const out = [route.start, ...via, route.goal];
    // home through the vias in reverse; a home among the vias (or the goal) is reached directly
    let back = [route.goal, ...[...via].reverse(), route.home];
    if (via.includes(route.home) || route.home === route.goal) {
      back = route.home !== route.goal ? [route.goal, route.home] : [];
    }
    return { out, back };
  }

  /**
   * The route's points and what is wrong with it: missing, unknown or repeated names, legs
   * that cross occupied cells of the taught map (a warning: the server has the last word).
   */
  check(waypoints, view, route = this.route()) {
    const byName = new Map(waypoints.map((w) => [w.name, w]));
    const messages = [];
    for (const [role, value] of [["start", route.start], ["goal", route.goal], ["home", route.home]]) {
      if (!value) messages.push(`Pick a ${role} waypoint.`);
    }
    const { out, back } = RoutePicker.legs(route);
    const named = out.filter((n) => n);
    const unknown = [...new Set([...named, route.home].filter((n) => n && !byName.has(n)))];
    if (unknown.length) messages.push(`Unknown waypoint ${unknown.join(", ")}.`);
    const twice = named.filter((n, i) => named.indexOf(n) !== i);
    if (twice.length) messages.push(`${[...new Set(twice)].join(", ")} appears twice.`);
    const points = [];
    [...out, ...back.slice(1)].forEach((n, i) => {
      if (n && byName.has(n)) points.push({ ...byName.get(n), back: i >= out.length });
    });
    const blocked = [];
    for (let i = 0; i + 1 < points.length; i++) {
      if (view && points[i].name !== points[i + 1].name && view.legBlocked(points[i], points[i + 1])) {
        blocked.push(i);
        messages.push(`Leg ${points[i].name} \u2192 ${points[i + 1].name} crosses an obstacle.`);
      }
    }
    const ok = messages.length === blocked.length;
    return { points, blocked, messages, ok };
  }
}
