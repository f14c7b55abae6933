#!/usr/bin/env python3
"""A minimal Language Server Protocol client over stdio, for testing Sprig's species
schema in yaml-language-server the way an editor uses it.

It starts the server, tells it (as VS Code's YAML extension does) that the schema applies
to every file, opens each file, waits for the server's diagnostics of each, answers
optional hover requests, and prints one JSON object: {"diagnostics": {path: [[line,
column, message], ...]}, "hovers": [text, ...]} with 1-based lines and columns.

Usage: lsp_client.py --server CMD --schema FILE|modeline [--hover PATH:LINE:COL]... FILE...
(`modeline`: no schema setting; each file names its own in a `# yaml-language-server:
$schema=PATH` first line.) tests/editor/run.py imports session().
"""
import argparse
import json
import os
import pathlib
import shlex
import subprocess
import sys
import threading
import time
import queue


class Server:
    def __init__(self, argv):
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL)
        self.next_id = 1
        self.inbox = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        out = self.proc.stdout
        while True:
            length = None
            while True:
                line = out.readline()
                if not line:
                    self.inbox.put(None)
                    return
                line = line.strip()
                if not line:
                    break
                name, _, value = line.partition(b":")
                if name.lower() == b"content-length":
                    length = int(value)
            self.inbox.put(json.loads(out.read(length)))

    def send(self, message):
        body = json.dumps(message).encode()
        self.proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        self.proc.stdin.flush()

    def notify(self, method, params):
        self.send({"jsonrpc": "2.0", "method": method, "params": params})

    def request(self, method, params):
        self.send({"jsonrpc": "2.0", "id": self.next_id, "method": method, "params": params})
        self.next_id += 1
        return self.next_id - 1

    def messages(self, deadline):
        """Yields the server's messages until the deadline (time.monotonic()); answers its
        requests (configuration, registration) on the way."""
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return
            try:
                m = self.inbox.get(timeout=left)
            except queue.Empty:
                return
            if m is None:
                raise SystemExit("lsp_client: the server exited")
            if "method" in m and "id" in m:  # a request from the server
                result = None
                if m["method"] == "workspace/configuration":
                    result = [self.settings.get(i.get("section"), None) for i in m["params"]["items"]]
                self.send({"jsonrpc": "2.0", "id": m["id"], "result": result})
                continue
            yield m


def session(server_argv, schema, files, hovers=(), timeout=60.0):
    """Runs one server session: the schema applies to every file (None: each file names
    its schema in a `# yaml-language-server: $schema=` line). Returns (diagnostics, hover
    texts): diagnostics maps each file to [[line, column, message], ...], 1-based."""
    schema_uri = pathlib.Path(schema).resolve().as_uri() if schema else None
    server = Server(list(server_argv) + ["--stdio"])
    server.settings = {"yaml": {"validate": True, "hover": True, "completion": True,
                                "schemas": {schema_uri: "*.yaml"} if schema_uri else {},
                                "schemaStore": {"enable": False}},
                       "http": {}, "[yaml]": {}, "editor": {}, "files": {}}
    deadline = time.monotonic() + timeout
    init = server.request("initialize", {
        "processId": os.getpid(), "rootUri": pathlib.Path.cwd().as_uri(),
        "capabilities": {"workspace": {"configuration": True},
                         "textDocument": {"publishDiagnostics": {},
                                          "hover": {"contentFormat": ["plaintext", "markdown"]}}}})
    for m in server.messages(deadline):
        if m.get("id") == init:
            break
    server.notify("initialized", {})
    server.notify("workspace/didChangeConfiguration", {"settings": server.settings})

    uris = {}
    for f in files:
        p = pathlib.Path(f).resolve()
        uris[p.as_uri()] = f
        server.notify("textDocument/didOpen", {"textDocument": {
            "uri": p.as_uri(), "languageId": "yaml", "version": 1, "text": p.read_text()}})
    diagnostics = {}
    for m in server.messages(deadline):
        if m.get("method") == "textDocument/publishDiagnostics" and m["params"]["uri"] in uris:
            diagnostics[uris[m["params"]["uri"]]] = [
                [d["range"]["start"]["line"] + 1, d["range"]["start"]["character"] + 1, d["message"]]
                for d in m["params"]["diagnostics"]]
            if len(diagnostics) == len(uris):
                break
    missing = [f for f in files if f not in diagnostics]
    if missing:
        server.proc.kill()
        raise SystemExit("lsp_client: no diagnostics within %g s for %s" % (timeout, ", ".join(missing)))

    texts = []
    for h in hovers:
        path, line, col = h.rsplit(":", 2)
        uri = pathlib.Path(path).resolve().as_uri()
        rid = server.request("textDocument/hover", {"textDocument": {"uri": uri},
                                                    "position": {"line": int(line) - 1, "character": int(col) - 1}})
        for m in server.messages(deadline):
            if m.get("id") == rid:
                r = m.get("result") or {}
                c = r.get("contents", "")
                texts.append(c.get("value", "") if isinstance(c, dict) else str(c))
                break
    server.request("shutdown", None)
    server.notify("exit", None)
    try:
        server.proc.wait(timeout=5)
    except subprocess.TimeoutExpired:
        server.proc.kill()
    return diagnostics, texts


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", required=True)
    ap.add_argument("--schema", required=True)
    ap.add_argument("--hover", action="append", default=[])
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("files", nargs="*")
    a = ap.parse_args()
    diagnostics, hovers = session(shlex.split(a.server), None if a.schema == "modeline" else a.schema,
                                  a.files, a.hover, a.timeout)
    json.dump({"diagnostics": diagnostics, "hovers": hovers}, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
