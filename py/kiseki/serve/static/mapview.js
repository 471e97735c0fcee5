// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The taught map on a canvas: world metres -> map cells (origin, resolution, y up) -> pixels.

const UNKNOWN = 205; // map_server's grey for unknown cells; 0 is occupied, 254 free
const ROBOT_LENGTH = 1.05; // CARTIS TypeB, metres (thesis, section 3.1)
const ROBOT_WIDTH = 0.58;
const INSET_M = 2.5; // the magnifier's side, metres

/** A map's grey levels (0 occupied .. 255 free) from a PNG bitmap or from JSON cells. */
function greyLevels(source) {
  if (source.json) {
    const m = source.json;
    const cells = m.cells || m.data;
    const width = m.width ?? cells[0].length;
    const height = m.height ?? cells.length;
    const flat = Array.isArray(cells[0]) ? cells.flat() : cells;
    const grey = new Uint8ClampedArray(width * height);
    // JSON rows run from y = origin upward (ROS OccupancyGrid order); images run top down
    for (let r = 0; r < height; r++) {
      for (let c = 0; c < width; c++) {
        const v = flat[r * width + c];
        const g = v < 0 ? UNKNOWN : Math.round(255 - (v * 255) / 100);
        grey[(height - 1 - r) * width + c] = g;
      }
    }
    return { grey, width, height };
  }
  const { bitmap } = source;
  const canvas = document.createElement("canvas");
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  const ctx = canvas.getContext("2d");
  ctx.drawImage(bitmap, 0, 0);
  const rgba = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
  const grey = new Uint8ClampedArray(bitmap.width * bitmap.height);
  for (let i = 0; i < grey.length; i++) grey[i] = rgba[4 * i];
  return { grey, width: bitmap.width, height: bitmap.height };
}

export class MapView {
  constructor(canvas, markers) {
    this.canvas = canvas;
    this.markers = markers;
    this.map = null; // {grey, width, height, resolution, origin}
    this.base = null; // the map drawn once, in map cells
    this.view = null; // cell window shown: {c0, r0, c1, r1}
    this.scale = 1; // CSS pixels per cell
    this.route = []; // [{x, y, back}] along the route, the way home last
    this.blocked = []; // indices of legs through occupied cells
    this.live = null;
    this.trail = [];
  }

  setMap(source, meta) {
    const { grey, width, height } = greyLevels(source);
    const origin = meta.origin || (source.json && source.json.origin) || [0, 0, 0];
    const resolution = meta.resolution || (source.json && source.json.resolution);
    this.map = { grey, width, height, resolution, origin };
    const base = document.createElement("canvas");
    base.width = width;
    base.height = height;
    const ctx = base.getContext("2d");
    const img = ctx.createImageData(width, height);
    for (let i = 0; i < grey.length; i++) {
      const g = grey[i];
      // occupied cells dark, free white, unknown a light blue-grey (legible on a projector)
      const [r, gg, b] = g < 100 ? [57, 64, 77] : g > 230 ? [255, 255, 255] : [214, 220, 228];
      img.data.set([r, gg, b, 255], 4 * i);
    }
    ctx.putImageData(img, 0, 0);
    this.base = base;
  }

  /** Frames the known part of the map and the waypoints, with a 1 m margin. */
  frame(waypoints) {
    const { grey, width, height, resolution } = this.map;
    let c0 = width;
    let r0 = height;
    let c1 = 0;
    let r1 = 0;
    for (let r = 0; r < height; r++) {
      for (let c = 0; c < width; c++) {
        if (grey[r * width + c] === UNKNOWN) continue;
        c0 = Math.min(c0, c);
        c1 = Math.max(c1, c + 1);
        r0 = Math.min(r0, r);
        r1 = Math.max(r1, r + 1);
      }
    }
    for (const w of waypoints) {
      const [c, r] = this.toCell(w.x, w.y);
      c0 = Math.min(c0, c);
      c1 = Math.max(c1, c);
      r0 = Math.min(r0, r);
      r1 = Math.max(r1, r);
    }
    if (c1 <= c0 || r1 <= r0) [c0, r0, c1, r1] = [0, 0, width, height];
    const m = 1.0 / resolution;
    this.view = {
      c0: Math.max(0, c0 - m), r0: Math.max(0, r0 - 2 * m), // room for the labels above
      c1: Math.min(width, c1 + m), r1: Math.min(height, r1 + m),
    };
  }

  toCell(x, y) {
    const { resolution, origin, height } = this.map;
    return [(x - origin[0]) / resolution, height - (y - origin[1]) / resolution];
  }

  /** World metres -> CSS pixels on the canvas. */
  toScreen(x, y) {
    const [c, r] = this.toCell(x, y);
    return [(c - this.view.c0) * this.scale, (r - this.view.r0) * this.scale];
  }

  /** Whether the straight leg a -> b crosses an occupied cell of the taught map. */
  legBlocked(a, b) {
    const { grey, width, height, resolution } = this.map;
    const steps = Math.ceil(Math.hypot(b.x - a.x, b.y - a.y) / (resolution / 2)) + 1;
    for (let i = 0; i <= steps; i++) {
      const t = i / steps;
      const [c, r] = this.toCell(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
      const ci = Math.floor(c);
      const ri = Math.floor(r);
      if (ci < 0 || ri < 0 || ci >= width || ri >= height) return true;
      if (grey[ri * width + ci] < 100) return true;
    }
    return false;
  }

  resize() {
    if (!this.view) return;
    const cssWidth = this.canvas.parentElement.parentElement.clientWidth - 2;
    const cells = this.view.c1 - this.view.c0;
    const rows = this.view.r1 - this.view.r0;
    const maxHeight = Math.max(320, window.innerHeight - this.canvas.getBoundingClientRect().top - 50);
    this.scale = Math.min(cssWidth / cells, maxHeight / rows);
    const ratio = window.devicePixelRatio || 1;
    this.canvas.style.width = `${cells * this.scale}px`;
    this.canvas.style.height = `${rows * this.scale}px`;
    this.canvas.width = Math.round(cells * this.scale * ratio);
    this.canvas.height = Math.round(rows * this.scale * ratio);
    this.markers.style.width = this.canvas.style.width;
    this.draw();
  }

  placeMarkers(waypoints, roles, onTap) {
    this.waypoints = waypoints;
    this.markers.replaceChildren();
    for (const w of waypoints) {
      const button = document.createElement("button");
      button.type = "button";
      button.className = "marker";
      button.dataset.waypoint = w.name;
      const tags = roles(w.name);
      button.dataset.roles = tags.join(" ");
      button.setAttribute("aria-label", `waypoint ${w.name}${tags.length ? ` (${tags.join(", ")})` : ""}`);
      button.textContent = w.name;
      if (tags.length) {
        const tag = document.createElement("span");
        tag.className = "tag";
        tag.textContent = tags.join(" / ");
        button.append(tag);
      }
      const [sx, sy] = this.toScreen(w.x, w.y);
      button.style.left = `${sx}px`;
      button.style.top = `${sy}px`;
      button.addEventListener("click", () => onTap(w.name));
      this.markers.append(button);
    }
  }

  draw() {
    const ctx = this.canvas.getContext("2d");
    const ratio = window.devicePixelRatio || 1;
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    ctx.clearRect(0, 0, this.canvas.width, this.canvas.height);
    if (!this.base || !this.view) return;
    const v = this.view;
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(this.base, v.c0, v.r0, v.c1 - v.c0, v.r1 - v.r0, 0, 0,
      (v.c1 - v.c0) * this.scale, (v.r1 - v.r0) * this.scale);
    this.drawGrid(ctx);
    this.drawRoute(ctx);
    this.drawWaypoints(ctx);
    if (this.live) this.drawLive(ctx, this.live);
  }

  /** Each waypoint's exact place: a ring with a stem up to its label (the label sits above). */
  drawWaypoints(ctx) {
    ctx.lineWidth = 3;
    ctx.strokeStyle = "#1b1f24";
    for (const w of this.waypoints || []) {
      const [sx, sy] = this.toScreen(w.x, w.y);
      ctx.beginPath();
      ctx.moveTo(sx, sy - 6);
      ctx.lineTo(sx, sy - 14);
      ctx.stroke();
      ctx.beginPath();
      ctx.arc(sx, sy, 6, 0, 2 * Math.PI);
      ctx.fillStyle = "#ffd166";
      ctx.fill();
      ctx.stroke();
    }
  }

  /** A 1 m grid, faint, so that a class can read distances off the map. */
  drawGrid(ctx) {
    const { resolution } = this.map;
    const [x0, y1] = this.toWorld(0, 0);
    const [x1, y0] = this.toWorld(this.canvas.clientWidth, this.canvas.clientHeight);
    ctx.strokeStyle = "rgba(31, 95, 191, 0.12)";
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let x = Math.ceil(x0); x <= x1; x++) {
      const [sx] = this.toScreen(x, 0);
      ctx.moveTo(sx, 0);
      ctx.lineTo(sx, this.canvas.clientHeight);
    }
    for (let y = Math.ceil(y0); y <= y1; y++) {
      const [, sy] = this.toScreen(0, y);
      ctx.moveTo(0, sy);
      ctx.lineTo(this.canvas.clientWidth, sy);
    }
    ctx.stroke();
    // scale bar: 1 m
    const px = this.scale / resolution;
    ctx.fillStyle = "#1b1f24";
    ctx.fillRect(12, this.canvas.clientHeight - 18, px, 5);
    ctx.font = "600 14px system-ui, 'DejaVu Sans', sans-serif";
    ctx.fillText("1 m", 16 + px, this.canvas.clientHeight - 12);
  }

  toWorld(sx, sy) {
    const { resolution, origin, height } = this.map;
    const c = sx / this.scale + this.view.c0;
    const r = sy / this.scale + this.view.r0;
    return [origin[0] + c * resolution, origin[1] + (height - r) * resolution];
  }

  drawRoute(ctx) {
    const pts = this.route;
    for (let i = 0; i + 1 < pts.length; i++) {
      let [ax, ay] = this.toScreen(pts[i].x, pts[i].y);
      let [bx, by] = this.toScreen(pts[i + 1].x, pts[i + 1].y);
      const back = pts[i + 1].back;
      if (back) {
        // the way home runs beside the way out, 7 px to its right
        const n = Math.hypot(bx - ax, by - ay) || 1;
        const [ox, oy] = [(-(by - ay) / n) * 7, ((bx - ax) / n) * 7];
        [ax, ay, bx, by] = [ax + ox, ay + oy, bx + ox, by + oy];
      }
      ctx.strokeStyle = this.blocked.includes(i) ? "#c0262d" : back ? "#b35c00" : "#1f5fbf";
      ctx.globalAlpha = 0.8;
      ctx.lineWidth = 6;
      ctx.setLineDash(back ? [12, 10] : []);
      ctx.beginPath();
      ctx.moveTo(ax, ay);
      ctx.lineTo(bx, by);
      ctx.stroke();
      this.arrowHead(ctx, ax, ay, bx, by);
    }
    ctx.setLineDash([]);
    ctx.globalAlpha = 1;
  }

  arrowHead(ctx, ax, ay, bx, by) {
    const mx = (ax + bx) / 2;
    const my = (ay + by) / 2;
    const a = Math.atan2(by - ay, bx - ax);
    ctx.fillStyle = ctx.strokeStyle;
    ctx.beginPath();
    ctx.moveTo(mx + 12 * Math.cos(a), my + 12 * Math.sin(a));
    ctx.lineTo(mx + 10 * Math.cos(a + 2.5), my + 10 * Math.sin(a + 2.5));
    ctx.lineTo(mx + 10 * Math.cos(a - 2.5), my + 10 * Math.sin(a - 2.5));
    ctx.fill();
  }

  setLive(live) {
    this.live = live;
    if (live && live.pose) {
      const last = this.trail[this.trail.length - 1];
      const [x, y] = live.pose;
      if (!last || Math.hypot(x - last[0], y - last[1]) > 0.05) this.trail.push([x, y]);
      if (this.trail.length > 2000) this.trail.shift();
    }
    this.draw();
  }

  drawLive(ctx, live) {
    const particles = live.particles || [];
    ctx.fillStyle = "rgba(123, 63, 196, 0.55)";
    const dot = Math.max(2, this.scale * 0.3);
    for (const p of particles) {
      const [sx, sy] = this.toScreen(p[0], p[1]);
      ctx.fillRect(sx - dot / 2, sy - dot / 2, dot, dot);
    }
    if (this.trail.length > 1) {
      ctx.strokeStyle = "rgba(27, 127, 59, 0.6)";
      ctx.lineWidth = 2;
      ctx.beginPath();
      this.trail.forEach(([x, y], i) => {
        const [sx, sy] = this.toScreen(x, y);
        if (i === 0) ctx.moveTo(sx, sy);
        else ctx.lineTo(sx, sy);
      });
      ctx.stroke();
    }
    const k = this.scale / this.map.resolution;
    const onMap = (x, y) => this.toScreen(x, y);
    if (live.pose) this.drawRobot(ctx, live.pose, "#1b7f3b", true, onMap, k);
    if (live.estimate) this.drawRobot(ctx, live.estimate, "#c0262d", false, onMap, k);
    if (live.estimate) this.drawInset(ctx, live);
  }

  /**
   * A magnifier in the top-right corner: INSET_M metres around the estimate, where the
   * particles (a few centimetres apart once the filter has converged) can be told apart.
   */
  drawInset(ctx, live) {
    const size = Math.min(220, this.canvas.clientWidth * 0.35);
    const [ex, ey] = live.estimate;
    const k = size / INSET_M; // pixels per metre
    const x0 = this.canvas.clientWidth - size - 10;
    const y0 = 10;
    const project = (x, y) => [x0 + size / 2 + (x - ex) * k, y0 + size / 2 - (y - ey) * k];
    const [c, r] = this.toCell(ex, ey);
    const half = INSET_M / 2 / this.map.resolution;
    ctx.save();
    ctx.fillStyle = "#fff";
    ctx.fillRect(x0, y0, size, size);
    ctx.beginPath();
    ctx.rect(x0, y0, size, size);
    ctx.clip();
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(this.base, c - half, r - half, 2 * half, 2 * half, x0, y0, size, size);
    if (live.pose) this.drawRobot(ctx, live.pose, "#1b7f3b", true, project, k);
    this.drawRobot(ctx, live.estimate, "#c0262d", false, project, k);
    ctx.fillStyle = "rgba(123, 63, 196, 0.7)"; // the particles on top, each one visible
    for (const p of live.particles || []) {
      const [sx, sy] = project(p[0], p[1]);
      ctx.fillRect(sx - 2, sy - 2, 4, 4);
    }
    ctx.restore();
    ctx.strokeStyle = "#1b1f24";
    ctx.lineWidth = 2;
    ctx.strokeRect(x0, y0, size, size);
    ctx.fillStyle = "rgba(255, 255, 255, 0.85)";
    ctx.fillRect(x0 + 1, y0 + size - 22, size - 2, 21);
    ctx.fillStyle = "#1b1f24";
    ctx.font = "600 13px system-ui, 'DejaVu Sans', sans-serif";
    ctx.fillText(`${INSET_M} m around the estimate`, x0 + 6, y0 + size - 7);
  }

  /** The robot's footprint (filled for the true pose, outlined for the estimate) and heading. */
  drawRobot(ctx, [x, y, theta], colour, filled, project, k) {
    const [sx, sy] = project(x, y); // k: pixels per metre
    ctx.save();
    ctx.translate(sx, sy);
    ctx.rotate(-theta); // y up in the world, down on the screen
    ctx.lineWidth = 3;
    ctx.strokeStyle = colour;
    ctx.fillStyle = filled ? `${colour}55` : "transparent";
    ctx.beginPath();
    ctx.rect((-ROBOT_LENGTH / 2) * k, (-ROBOT_WIDTH / 2) * k, ROBOT_LENGTH * k, ROBOT_WIDTH * k);
    ctx.fill();
    ctx.stroke();
    ctx.beginPath();
    ctx.moveTo(0, 0);
    ctx.lineTo((ROBOT_LENGTH / 2 + 0.25) * k, 0);
    ctx.stroke();
    ctx.beginPath();
    ctx.arc(0, 0, 4, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
    ctx.restore();
  }
}
