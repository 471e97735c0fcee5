// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The JSON API and the live websocket, with the access token kept from #token=... or typed once.
// The token travels in the URL's fragment (never sent to the server, so in no log), then in the
// Authorization header and the websocket's subprotocol, never in a URL the server sees.

const TOKEN_KEY = "kiseki.token";

export class ApiError extends Error {
  constructor(status, detail) {
    super(detail);
    this.status = status;
  }
}

/** The token from the URL's #token=... (then removed from the address bar) or earlier visits. */
export function loadToken() {
  const fragment = new URLSearchParams(window.location.hash.slice(1));
  const fromUrl = fragment.get("token");
  if (fromUrl) {
    saveToken(fromUrl);
    fragment.delete("token");
    const rest = fragment.toString();
    const url = window.location.pathname + window.location.search + (rest ? `#${rest}` : "");
    window.history.replaceState(null, "", url);
    return fromUrl;
  }
  try {
    return window.localStorage.getItem(TOKEN_KEY) || "";
  } catch {
    return "";
  }
}

export function saveToken(token) {
  try {
    window.localStorage.setItem(TOKEN_KEY, token);
  } catch {
    // private mode: the token lives for this page only
  }
}

/** A FastAPI error body's detail as one line (a string, or a list of validation errors). */
function detailText(body, status) {
  const detail = body && body.detail;
  if (typeof detail === "string") return detail;
  if (Array.isArray(detail)) {
    return detail.map((d) => (d.loc ? `${d.loc.join(".")}: ${d.msg}` : d.msg || "")).join("; ");
  }
  return `HTTP ${status}`;
}

export class Api {
  constructor(token) {
    this.token = token;
  }

  headers(extra = {}) {
    const h = { ...extra };
    if (this.token) h.Authorization = `Bearer ${this.token}`;
    return h;
  }

  async request(method, path, body) {
    const init = { method, headers: this.headers(), cache: "no-store" };
    if (body !== undefined) {
      init.headers["Content-Type"] = "application/json";
      init.body = JSON.stringify(body);
    }
    const response = await fetch(path, init);
    const type = response.headers.get("Content-Type") || "";
    const data = type.includes("json") ? await response.json().catch(() => null) : null;
    if (!response.ok) throw new ApiError(response.status, detailText(data, response.status));
    return data;
  }

  waypoints() { return this.request("GET", "api/waypoints"); }
  state() { return this.request("GET", "api/state"); }
  startRoute(route) { return this.request("POST", "api/routes", route); }
  stop() { return this.request("POST", "api/stop", {}); } // JSON, as every change must be
  rename(name, newName) {
    return this.request("PATCH", `api/waypoints/${encodeURIComponent(name)}`, { name: newName });
  }

  /** The taught map: a PNG (an Image) or JSON cells, as {image: CanvasImageSource, meta}. */
  async map() {
    const response = await fetch("api/map", { headers: this.headers(), cache: "no-store" });
    if (!response.ok) {
      const data = await response.json().catch(() => null);
      throw new ApiError(response.status, detailText(data, response.status));
    }
    const type = response.headers.get("Content-Type") || "";
    if (type.includes("json")) return { json: await response.json() };
    return { bitmap: await createImageBitmap(await response.blob()) };
  }

  websocketUrl() {
    const url = new URL("ws", window.location.href);
    url.protocol = url.protocol === "https:" ? "wss:" : "ws:";
    url.hash = "";
    return url.toString();
  }

  /** The websocket's subprotocols: the server answers "kiseki"; the token rides along. */
  websocketProtocols() {
    return this.token ? ["kiseki", `kiseki.token.${this.token}`] : ["kiseki"];
  }
}

/**
 * The live view's websocket: reopens with exponential backoff (0.5 s doubling to 8 s) whenever
 * it drops, calling onOpen (to refetch /api/state) before messages flow again.
 */
export class LiveSocket {
  constructor(api, { onMessage, onOpen, onStatus }) {
    this.api = api;
    this.onMessage = onMessage;
    this.onOpen = onOpen;
    this.onStatus = onStatus;
    this.delay = 500;
    this.socket = null;
    this.timer = null;
    this.closed = false;
  }

  open() {
    this.closed = false;
    clearTimeout(this.timer);
    const socket = new WebSocket(this.api.websocketUrl(), this.api.websocketProtocols());
    this.socket = socket;
    socket.onopen = () => {
      this.delay = 500;
      this.onStatus("live");
      this.onOpen();
    };
    socket.onmessage = (event) => {
      try {
        this.onMessage(JSON.parse(event.data));
      } catch (err) {
        console.error("bad live message", err);
      }
    };
    socket.onclose = () => {
      if (this.socket !== socket || this.closed) return;
      this.onStatus("reconnecting");
      this.timer = setTimeout(() => this.open(), this.delay);
      this.delay = Math.min(this.delay * 2, 8000);
    };
  }

  close() {
    this.closed = true;
    clearTimeout(this.timer);
    if (this.socket) this.socket.close();
  }
}
