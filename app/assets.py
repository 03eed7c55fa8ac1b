"""Static files under versioned URLs: cached by the browser for a year, fetched again on a change.

Each served folder has a version, a short hash: of every file's content for the app's own
``static/`` (recomputed when a file changes, so editing a page still needs only a reload), of the
package's name and version for the folders installed packages ship (MathJax, plotly, Swagger UI).
A page asks ``asset("js/scene.js")`` and gets ``/static/<version>/js/scene.js``.

The version names the whole folder, not one file: the pages are ES modules that import each other
by relative paths (``import ... from "./api.js"``), so a module under ``/static/<version>/js/``
imports its neighbours from the same versioned folder, each module is loaded once, and no file of
an old version is ever mixed with one of a new version. (A per-file hash would need every import
rewritten, a build step the pages do not have.)

- ``/static/<current version>/...``: ``Cache-Control: public, max-age=31536000, immutable``.
- ``/static/...`` (no version) or an old version: ``no-cache``, so the browser revalidates with its
  ETag and gets a 304 when nothing changed; an old page still works, and never pins new content
  under an old URL for a year.

Compressible files are gzipped once and kept in memory (plotly's 4.8 MB bundle takes ~0.3 s to
compress, which a room of students opening a page at once would otherwise pay per request).
"""

from __future__ import annotations

import gzip
import hashlib
import os
import re
import time
from collections import OrderedDict
from collections.abc import Callable
from functools import partial
from importlib import metadata
from pathlib import Path

import anyio
import anyio.to_thread
from starlette.datastructures import Headers
from starlette.responses import FileResponse, Response
from starlette.staticfiles import StaticFiles
from starlette.types import Scope

IMMUTABLE = "public, max-age=31536000, immutable"
REVALIDATE = "no-cache"

#: What a version segment looks like (hex digits of a sha256).
_VERSION = re.compile(r"[0-9a-f]{12}")
_COMPRESSIBLE = ("text/", "application/javascript", "application/json", "image/svg+xml")
#: Smaller files gain too little from gzip to be worth a header.
_MIN_GZIP_BYTES = 1024
_SCOPE_KEY = "lagrange_lab.asset_version"


def content_version(directory: Path, recheck_seconds: float = 1.0) -> Callable[[], str]:
    """The version of a folder whose files may change: a hash of every file's path and bytes.

    The files are hashed again only when a stat of the tree (names, sizes, mtimes) differs, and
    the tree is stat'ed at most once per ``recheck_seconds``: a page view costs no hashing.
    """
    state = {"checked": -float("inf"), "signature": None, "version": ""}

    def version() -> str:
        now = time.monotonic()
        if now - state["checked"] < recheck_seconds:
            return state["version"]
        state["checked"] = now
        files = sorted(p for p in directory.rglob("*") if p.is_file())
        stats = [p.stat() for p in files]
        signature = [(p, s.st_mtime_ns, s.st_size) for p, s in zip(files, stats, strict=True)]
        if signature != state["signature"]:
            digest = hashlib.sha256()
            for path in files:
                digest.update(path.relative_to(directory).as_posix().encode() + b"\0")
                digest.update(path.read_bytes() + b"\0")
            state["signature"], state["version"] = signature, digest.hexdigest()[:12]
        return state["version"]

    return version


def package_version(distribution: str) -> Callable[[], str]:
    """The version of a folder an installed package ships: it changes with the package."""
    try:
        label = f"{distribution}=={metadata.version(distribution)}"
    except metadata.PackageNotFoundError:
        label = distribution
    fixed = hashlib.sha256(label.encode()).hexdigest()[:12]
    return lambda: fixed


class VersionedStaticFiles(StaticFiles):
    """``StaticFiles`` that serves ``<version>/path`` as ``path``, with the caching it earns."""

    def __init__(self, directory: Path, version: Callable[[], str]) -> None:
        super().__init__(directory=directory, check_dir=False)
        self.version = version
        self._gzipped = GzipCache()

    def get_path(self, scope: Scope) -> str:
        path = super().get_path(scope)
        head, sep, rest = path.partition(os.sep)
        if sep and _VERSION.fullmatch(head):
            scope[_SCOPE_KEY] = head
            return rest
        return path

    async def get_response(self, path: str, scope: Scope) -> Response:
        response = await super().get_response(path, scope)
        current = scope.get(_SCOPE_KEY) == self.version()
        response.headers["Cache-Control"] = IMMUTABLE if current else REVALIDATE
        if isinstance(response, FileResponse) and _gzip_worthwhile(response, scope):
            return await self._gzipped.response(response, Headers(scope=scope))
        return response


def _gzip_worthwhile(response: FileResponse, scope: Scope) -> bool:
    if "gzip" not in Headers(scope=scope).get("accept-encoding", ""):
        return False
    size = response.stat_result.st_size if response.stat_result else 0
    media_type = response.media_type or ""
    return size >= _MIN_GZIP_BYTES and media_type.startswith(_COMPRESSIBLE)


class GzipCache:
    """Files' gzipped bytes, keyed by path, mtime and size, the least recently used dropped first
    past ``max_bytes``; a file is compressed by one request while the others wait for it."""

    def __init__(self, max_bytes: int = 64 * 1024 * 1024) -> None:
        self.max_bytes = max_bytes
        self._entries: OrderedDict[tuple, bytes] = OrderedDict()
        self._lock = anyio.Lock()

    async def response(self, file: FileResponse, request_headers: Headers) -> Response:
        """The gzipped twin of ``file``: its headers, its own ETag, 304 when the client has it."""
        assert file.stat_result is not None
        st = file.stat_result
        headers = {k: v for k, v in file.headers.items() if k not in ("content-length", "etag")}
        headers["etag"] = file.headers["etag"][:-1] + '-gzip"'
        headers["content-encoding"] = "gzip"
        headers["vary"] = "Accept-Encoding"
        if headers["etag"] in _etags(request_headers.get("if-none-match", "")):
            headers.pop("content-encoding")
            return Response(status_code=304, headers=headers)
        body = await self._get((str(file.path), st.st_mtime_ns, st.st_size), Path(file.path))
        return Response(body, headers=headers, media_type=file.media_type)

    async def _get(self, key: tuple, path: Path) -> bytes:
        async with self._lock:
            if key not in self._entries:
                raw = await anyio.to_thread.run_sync(path.read_bytes)
                self._entries[key] = await anyio.to_thread.run_sync(
                    partial(gzip.compress, raw, 9, mtime=0)
                )
                while sum(map(len, self._entries.values())) > self.max_bytes > 0:
                    self._entries.popitem(last=False)
            self._entries.move_to_end(key)
            return self._entries[key]


def _etags(header: str) -> list[str]:
    return [tag.strip().removeprefix("W/") for tag in header.split(",") if tag.strip()]


#: Lighter files the app ships in place of a package's, by the path a page asks for: the pages
#: draw only scatter traces, which plotly's partial "basic" bundle has (static/vendor/, from npm's
#: plotly.js-basic-dist-min of the same plotly.js version, MIT): 1.2 MB and 395 kB gzipped,
#: against 4.8 MB and 1.47 MB for the full bundle the plotly package ships.
SUBSTITUTES = {"vendor/plotly.min.js": "vendor/plotly-basic/plotly.min.js"}


#: A static import in an ES module: ``import {a} from "./x.js"``, ``import "./x.js"``,
#: ``export {a} from "./x.js"`` (relative paths only; a dynamic ``import("./x.js")`` is left to
#: load when it is asked for).
_STATIC_IMPORT = re.compile(
    r"^\s*(?:import|export)\s(?:[^\"';]*?\sfrom\s*)?[\"'](\.{1,2}/[^\"']+)[\"']", re.MULTILINE
)


def module_graph(directory: Path, entry: str) -> list[str]:
    """``entry`` (a path under ``directory``) and every module it imports statically, directly or
    not, breadth first: the files a browser needs before the entry can run.

    The browser finds them one level at a time (it reads scene.js, then fetches its imports, then
    theirs): three round trips for the scene page's 25 modules. Named up front in
    ``<link rel="modulepreload">`` they are all fetched at once while the page is still parsing.
    """
    order, seen = [], {entry}
    queue = [entry]
    while queue:
        path = queue.pop(0)
        order.append(path)
        try:
            text = (directory / path).read_text(encoding="utf-8")
        except OSError:
            continue
        for match in _STATIC_IMPORT.finditer(text):
            target = os.path.normpath(os.path.join(os.path.dirname(path), match.group(1)))
            target = Path(target).as_posix()
            if target not in seen and not target.startswith(".."):
                seen.add(target)
                queue.append(target)
    return order


class Assets:
    """The served folders by URL prefix, and the versioned URL of any file in them."""

    def __init__(self) -> None:
        self.folders: dict[str, VersionedStaticFiles] = {}
        self._graphs: dict[tuple[str, str], list[str]] = {}

    def add(self, prefix: str, directory: Path, version: Callable[[], str]) -> VersionedStaticFiles:
        """Serve ``directory`` under ``prefix`` (mount the returned app there)."""
        self.folders[prefix] = VersionedStaticFiles(directory, version)
        return self.folders[prefix]

    def url(self, path: str) -> str:
        """``/static/<version>/<rest>`` for ``path`` under /static, from the folder that holds it:
        ``url("js/scene.js")``, ``url("mathjax/es5/tex-svg.js")``. A path with a lighter
        substitute the app ships (`SUBSTITUTES`) names the substitute."""
        path = path.lstrip("/")
        substitute = SUBSTITUTES.get(path)
        if substitute and self._holder(substitute):
            path = substitute
        found = self._holder(path) or self._holder(path, must_exist=False)
        if found is None:
            raise KeyError(f"no served folder holds {path!r}")
        prefix, rest = found
        return f"{prefix}/{self.folders[prefix].version()}/{rest}"

    def module_urls(self, entry: str) -> list[str]:
        """The versioned URLs of ``entry`` (``"js/scene.js"``) and of every module it imports
        statically (`module_graph`), read again only when the folder's version changes."""
        found = self._holder(entry)
        if found is None:
            return []
        prefix, rest = found
        folder = self.folders[prefix]
        version = folder.version()
        key = (entry, version)
        if key not in self._graphs:
            self._graphs = {k: v for k, v in self._graphs.items() if k[1] == version}
            self._graphs[key] = module_graph(Path(folder.directory), rest)
        return [f"{prefix}/{version}/{path}" for path in self._graphs[key]]

    def _holder(self, path: str, must_exist: bool = True) -> tuple[str, str] | None:
        """The longest served prefix whose folder has ``path`` (``must_exist``), or that would
        serve it: the app's own static/vendor/ is reached through /static although plotly's
        folder is mounted at /static/vendor."""
        full = "/static/" + path
        for prefix in sorted(self.folders, key=len, reverse=True):
            if full.startswith(prefix + "/"):
                rest = full[len(prefix) + 1 :]
                folder = self.folders[prefix].directory
                if not must_exist or (folder is not None and (Path(folder) / rest).is_file()):
                    return prefix, rest
        return None
