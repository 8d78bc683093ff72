// The JSON API of `thzmap serve` (docs/gui.md), same origin, authorised by the cookie the
// token URL set. Every failure becomes an Error whose message is the server's.

export async function request(path, options = {}) {
  let response;
  try {
    response = await fetch(path, { credentials: "same-origin", ...options });
  } catch (e) {
    // no answer at all ("Failed to fetch"): the server stopped, or the network is down
    if (e.name !== "TypeError") throw e; // a timeout or an abort says so itself
    throw new Error(`${path.split("?")[0]}: the server does not answer (stopped?); start ` +
      "thzmap serve again and reload the page");
  }
  if (!response.ok) {
    let message = response.statusText;
    try {
      const body = await response.json();
      message = body.error || body.message || JSON.stringify(body);
      // where in the request body the problem is: "$.options.seed"
      if (body.path) message += ` (at ${body.path})`;
    } catch (_) {
      /* not JSON: the status text says enough */
    }
    throw new Error(`${path.split("?")[0]}: ${response.status} ${message}`);
  }
  return response;
}

export const q = (value) => encodeURIComponent(value);
export const getJSON = async (path) => (await request(path)).json();
export const getText = async (path) => (await request(path)).text();
export const getBytes = async (path) => (await request(path)).arrayBuffer();
export const sendJSON = async (method, path, body, signal) =>
  (await request(path, {
    method,
    signal,
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify(body),
  })).json();
export const putText = (path, text) =>
  request(path, { method: "PUT", headers: { "Content-Type": "application/json" }, body: text });
export const del = (path) => request(path, { method: "DELETE" });

const statusLine = () => document.getElementById("status");
export function status(message, isError = false) {
  const el = statusLine();
  el.textContent = message;
  el.classList.toggle("error", isError);
}
export function reportError(error) {
  console.error(error);
  status(String(error.message || error), true);
}
