// The page's only way to the server: the authenticated REST API (docs/api.md) with the bearer token the
// user signed in with. The token lives in sessionStorage for this browser tab's session only and goes
// nowhere but into the Authorization header of requests to this server: never into a URL or a log.

const TOKEN_KEY = 'rcfd-token';

export const session = {
  token: () => sessionStorage.getItem(TOKEN_KEY),
  signIn: (token) => sessionStorage.setItem(TOKEN_KEY, token),
  signOut: () => sessionStorage.removeItem(TOKEN_KEY),
};

/// An answer that is not 2xx: its status and the problem (RFC 9457) the server sent, whose `errors`
/// carry a JSON pointer each for invalid input.
export class ApiError extends Error {
  constructor(status, problem, fallback) {
    super(problem?.detail || problem?.title || fallback || `HTTP ${status}`);
    this.status = status;
    this.problem = problem || null;
    this.errors = Array.isArray(problem?.errors) ? problem.errors : [];
  }
}

async function problemOf(response) {
  try {
    return await response.json();
  } catch {
    return null;
  }
}

/// A request to the API; resolves to the parsed JSON body, or to the Response with { raw: true }.
/// A 401 signs the user out (the token is wrong or the server has another one now).
export async function api(path, { method = 'GET', json, body, headers = {}, raw = false, token } = {}) {
  const sendHeaders = { Authorization: `Bearer ${token ?? session.token() ?? ''}`, ...headers };
  let sendBody = body;
  if (json !== undefined) {
    sendHeaders['Content-Type'] = 'application/json';
    sendBody = JSON.stringify(json);
  }
  const response = await fetch(path, {
    method, headers: sendHeaders, body: sendBody, cache: 'no-store', credentials: 'omit', redirect: 'error',
  });
  if (!response.ok) {
    const problem = await problemOf(response);
    if (response.status === 401 && token === undefined) {
      session.signOut();
      window.dispatchEvent(new Event('rcfd:signed-out'));
    }
    throw new ApiError(response.status, problem, response.statusText);
  }
  if (raw) return response;
  return response.json();
}

/// Saves what `path` answers as a file named `filename`: fetched with the token, handed to the browser
/// as a blob: URL (so the token never appears in a link).
export async function download(path, filename) {
  const response = await api(path, { raw: true });
  const blob = await response.blob();
  const url = URL.createObjectURL(blob);
  const link = document.createElement('a');
  link.href = url;
  link.download = filename;
  link.hidden = true;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60_000);
  return blob.size;
}

/// A blob: URL of what `path` answers (an SVG figure shown as an <img>: the page's CSP allows blob:
/// images, and an SVG in an <img> runs no script).
export async function objectUrl(path) {
  const response = await api(path, { raw: true });
  return URL.createObjectURL(await response.blob());
}

/// POST /v1/databases with upload progress (XMLHttpRequest: fetch reports none); `onProgress(sent,
/// total)` while the body goes out. Resolves to the database's record.
export function uploadDatabase(file, onProgress) {
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open('POST', '/v1/databases');
    xhr.setRequestHeader('Authorization', `Bearer ${session.token() ?? ''}`);
    xhr.setRequestHeader('Content-Type', 'application/x-hdf5');
    xhr.responseType = 'json';
    xhr.upload.addEventListener('progress', (e) => onProgress(e.loaded, e.lengthComputable ? e.total : file.size));
    xhr.addEventListener('load', () => {
      if (xhr.status === 201) return resolve(xhr.response);
      if (xhr.status === 401) {
        session.signOut();
        window.dispatchEvent(new Event('rcfd:signed-out'));
      }
      reject(new ApiError(xhr.status, xhr.response, xhr.statusText));
    });
    xhr.addEventListener('error', () => reject(new ApiError(0, null, 'the upload failed: no answer from the server')));
    xhr.addEventListener('abort', () => reject(new ApiError(0, null, 'the upload was cancelled')));
    xhr.send(file);
  });
}
