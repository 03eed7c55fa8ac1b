// What both assignment pages share: the reader's token (typed once, or given in the link's
// fragment #token=..., kept in this tab's sessionStorage) and API calls that send it.

import { ApiError, busy, track } from "./api.js";

const KEY = "lagrange-lab-token";

/** The token from the link's fragment (then removed from the address bar) or this tab's store. */
export function token() {
  const match = /(?:^|[#&])token=([^&]+)/.exec(location.hash);
  if (match) {
    sessionStorage.setItem(KEY, decodeURIComponent(match[1]));
    history.replaceState(null, "", location.pathname + location.search);
  }
  return sessionStorage.getItem(KEY);
}

/** Show the token form until a token is given; resolves with it. */
export function askToken() {
  const form = document.getElementById("token-form");
  const have = token();
  if (have) return Promise.resolve(have);
  form.hidden = false;
  document.getElementById("token").focus();
  return new Promise((resolve) => {
    form.addEventListener("submit", (event) => {
      event.preventDefault();
      const value = document.getElementById("token").value.trim();
      if (!value) return;
      sessionStorage.setItem(KEY, value);
      form.hidden = true;
      resolve(value);
    });
  });
}

export function forgetToken() {
  sessionStorage.removeItem(KEY);
}

/** fetch with the token; an error answer throws ApiError with the API's field details. */
export async function api(url, { method = "GET", body, raw = false } = {}) {
  const done = busy("Waiting for the server…");
  const headers = { Authorization: `Bearer ${token()}` };
  if (body !== undefined) headers["content-type"] = "application/json";
  try {
    const r = await track(fetch(url, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) }));
    if (raw && r.ok) return r;
    const data = await r.json().catch(() => ({}));
    if (!r.ok) throw new ApiError(r.status, data.detail ?? r.statusText);
    return data;
  } finally {
    done();
  }
}

/** Say something in the page's live status line. */
export function say(text, bad = false) {
  const status = document.getElementById("status");
  status.textContent = text;
  status.classList.toggle("bad", bad);
}

/** An element with text (never HTML from the server). */
export function el(tag, text = "", attrs = {}) {
  const node = document.createElement(tag);
  if (text) node.textContent = text;
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  return node;
}

export const inlineMath = (text) => text.replace(/\$([^$]+)\$/g, "\\($1\\)");
