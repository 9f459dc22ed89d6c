// The page talks only to the public HTTP API (/v1/..., /limits); see /openapi.json.

/** An API failure: HTTP status and the `{"error":{code,message,location}}` body. */
export class ApiError extends Error {
  constructor(status, code, message, location) {
    super(message);
    this.status = status;
    this.code = code;
    this.location = location ?? null;
  }
}

/** The media type to send a file as, from its name (the server also sniffs the content). */
export function mediaType(name) {
  const n = name.toLowerCase();
  if (/\.(step|stp|p21)$/.test(n)) return 'model/step';
  if (/\.(igs|iges)$/.test(n)) return 'model/iges';
  if (n.endsWith('.json')) return 'application/json';
  return 'application/octet-stream';
}

/**
 * POSTs a body with XMLHttpRequest (which reports upload progress).
 * onUpload(sentBytes) is called as the body goes out.
 * Resolves with {status, headers, body} (body as `responseType`); rejects with ApiError.
 */
export function post(url, body, { contentType, accept, responseType = 'json', onUpload } = {}) {
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open('POST', url);
    if (contentType) xhr.setRequestHeader('Content-Type', contentType);
    if (accept) xhr.setRequestHeader('Accept', accept);
    xhr.responseType = responseType === 'json' ? 'text' : responseType;
    if (onUpload) xhr.upload.onprogress = (e) => onUpload(e.loaded);
    xhr.onerror = () =>
      reject(new ApiError(0, 'network', 'The connection to the server failed (network error or the server closed it).'));
    xhr.ontimeout = () => reject(new ApiError(0, 'timeout', 'The server did not answer in time.'));
    xhr.onload = async () => {
      if (xhr.status >= 200 && xhr.status < 300) {
        let data = xhr.response;
        if (responseType === 'json') {
          try {
            data = JSON.parse(xhr.response);
          } catch {
            reject(new ApiError(xhr.status, 'reply', 'The server reply is not JSON.'));
            return;
          }
        }
        resolve({ status: xhr.status, xhr, body: data });
        return;
      }
      reject(await errorOf(xhr));
    };
    xhr.send(body);
  });
}

/** The ApiError of a failed reply, whatever its responseType. */
async function errorOf(xhr) {
  let text = '';
  try {
    if (xhr.responseType === 'arraybuffer' && xhr.response) {
      text = new TextDecoder().decode(xhr.response);
    } else if (xhr.responseType === 'blob' && xhr.response) {
      text = await xhr.response.text();
    } else {
      text = xhr.responseText ?? '';
    }
  } catch {
    text = '';
  }
  try {
    const e = JSON.parse(text).error;
    return new ApiError(xhr.status, e.code, e.message, e.location);
  } catch {
    return new ApiError(xhr.status, 'http', `The server answered ${xhr.status} ${xhr.statusText}.`);
  }
}

/** GET JSON. */
export async function getJson(url) {
  const r = await fetch(url);
  if (!r.ok) throw new ApiError(r.status, 'http', `GET ${url}: ${r.status}`);
  return r.json();
}

/** "12.3 MB" */
export function bytes(n) {
  if (n < 1024) return `${n} bytes`;
  const units = ['KiB', 'MiB', 'GiB'];
  let v = n;
  let i = -1;
  do {
    v /= 1024;
    i += 1;
  } while (v >= 1024 && i < units.length - 1);
  return `${v.toFixed(v < 10 ? 1 : 0)} ${units[i]}`;
}

/** "line 12:4 (#40, D 7)" from a diagnostic location. */
export function locationText(loc) {
  if (!loc) return '';
  const parts = [];
  if (loc.line != null) parts.push(`line ${loc.line}${loc.column != null ? `:${loc.column}` : ''}`);
  if (loc.section && loc.sequence != null) {
    parts.push(`${loc.section} section, sequence ${loc.sequence}${loc.line == null && loc.column != null ? `, column ${loc.column}` : ''}`);
  }
  if (loc.entity) parts.push(`entity ${loc.entity}`);
  return parts.join(', ');
}
