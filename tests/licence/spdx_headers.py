#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""SPDX-License-Identifier lines of aggrelod's source files (LICENSE explains the split).

    spdx_headers.py check REPO_ROOT    every source file has the line its place asks for
    spdx_headers.py apply REPO_ROOT    adds the missing lines (never changes an existing one)
    spdx_headers.py selftest TMP_DIR   the check finds planted problems in a small tree

The runtime and what an engine copies or builds with it is MIT; the rest (module/, bake/,
planning/, the other samples and tests) is AGPL-3.0-or-later. The line goes first, or right
after a `#!` line or an HTML doctype. Files are those git tracks (node_modules, build trees and
generated files are never tracked); without git, a walk that skips those folders.
Exit status: 0 when all is well, 1 with one line per problem otherwise.
"""
import os
import re
import subprocess
import sys

MIT = "MIT"
AGPL = "AGPL-3.0-or-later"

# Folders and files under MIT besides runtime/ (see LICENSE).
MIT_PREFIXES = (
    "runtime/",
    "cmake/",
    "samples/web/",
    "samples/viewer/",
    "tests/viewer/",
    "tests/package_consumer/",
    "tests/runtime_only/",
    "tests/runtime_support/",
    "tests/windows/",
    "tests/validator/",
    "tests/licence/",
)
MIT_FILES = {
    "CMakeLists.txt",
    "samples/hello_runtime.c",
    "tests/unit/test_runtime_c_api.cpp",
    "tests/unit/test_runtime_collision.cpp",
    "tests/unit/test_runtime_format.cpp",
    "tests/unit/test_runtime_mapped_file.cpp",
    "tests/unit/test_runtime_selection.cpp",
    "tests/unit/test_selection_allocations.cpp",
}
# Source files everywhere in these folders (and the top-level CMakeLists.txt) carry the line.
SCOPE = ("runtime/", "module/", "bake/", "planning/", "samples/", "tests/", "cmake/")

SLASH, BLOCK, HASH, HTML = "//", "/*", "#", "<!--"
STYLE_BY_SUFFIX = [
    (".cpp", SLASH), (".cc", SLASH), (".hpp", SLASH), (".h", SLASH), (".c", BLOCK),
    (".js", SLASH), (".mjs", SLASH),
    (".cmake", HASH), (".cmake.in", HASH), (".pc.in", HASH), (".sh", HASH), (".py", HASH),
    (".html", HTML),
]
# C headers (compiled as C by engines): block comments as in their bodies.
C_HEADERS = {"runtime/include/aggrelod_runtime.h"}

SPDX_RE = re.compile(r"SPDX-License-Identifier:\s*([A-Za-z0-9.+-]+)")


def style_of(path):
    if os.path.basename(path) == "CMakeLists.txt":
        return HASH
    if path in C_HEADERS:
        return BLOCK
    for suffix, style in STYLE_BY_SUFFIX:
        if path.endswith(suffix):
            return style
    return None


def licence_of(path):
    if path in MIT_FILES or path.startswith(MIT_PREFIXES):
        return MIT
    return AGPL


def in_scope(path):
    if "/node_modules/" in path or style_of(path) is None:
        return False
    return path == "CMakeLists.txt" or path.startswith(SCOPE)


def header_line(style, licence):
    text = "SPDX-License-Identifier: " + licence
    return {SLASH: "// " + text, BLOCK: "/* " + text + " */", HASH: "# " + text,
            HTML: "<!-- " + text + " -->"}[style]


def tracked_files(root):
    try:
        top = subprocess.run(["git", "-C", root, "rev-parse", "--show-toplevel"], check=True,
                             capture_output=True, text=True).stdout.strip()
        if os.path.realpath(top) != os.path.realpath(root):
            raise OSError("not the top of a git work tree")  # e.g. a folder inside a build tree
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], check=True,
                             capture_output=True).stdout.decode("utf-8")
        return sorted(p for p in out.split("\0") if p and os.path.isfile(os.path.join(root, p)))
    except (OSError, subprocess.CalledProcessError):
        files = []
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames[:] = [d for d in dirnames if d not in ("node_modules", ".git", "out")
                           and not d.startswith("build")]
            for name in filenames:
                files.append(os.path.relpath(os.path.join(dirpath, name), root).replace(os.sep, "/"))
        return sorted(files)


def insertion_index(lines):
    """Index of the line the SPDX line belongs at."""
    if lines and (lines[0].startswith("#!") or lines[0].lower().startswith("<!doctype")):
        return 1
    return 0


def selftest(tmp):
    """A tree with four planted problems and one good file: check must report exactly those
    four, apply must add the one missing line and leave the wrong ones alone."""
    import shutil
    root = os.path.join(tmp, "spdx_selftest")
    shutil.rmtree(root, ignore_errors=True)
    files = {
        "runtime/src/a.cpp": "// SPDX-License-Identifier: AGPL-3.0-or-later\nint a;\n",  # wrong id
        "module/src/b.cpp": "int b;\n",                                                  # missing
        "bake/c.sh": "#!/bin/sh\necho\n# SPDX-License-Identifier: AGPL-3.0-or-later\n",  # wrong line
        "tests/unit/test_runtime_format.cpp": "// SPDX-License-Identifier: AGPL-3.0-or-later\n",  # MIT file
        "planning/d.h": "// SPDX-License-Identifier: AGPL-3.0-or-later\n#pragma once\n",  # good
    }
    for path, text in files.items():
        os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
        with open(os.path.join(root, path), "w") as f:
            f.write(text)
    def run(mode):
        out = subprocess.run([sys.executable, __file__, mode, root], capture_output=True, text=True)
        print(out.stdout, end="")
        return out.returncode, [l for l in out.stdout.splitlines() if not l.startswith("spdx_headers:")]
    code, problems = run("check")
    ok = code == 1 and len(problems) == 4 and all(any(l.startswith(p) for l in problems) for p in
                                                   ("runtime/src/a.cpp:1", "module/src/b.cpp:", "bake/c.sh:3",
                                                    "tests/unit/test_runtime_format.cpp:1"))
    run("apply")
    with open(os.path.join(root, "module/src/b.cpp")) as f:
        ok = ok and f.read() == "// SPDX-License-Identifier: AGPL-3.0-or-later\nint b;\n"
    code, problems = run("check")
    ok = ok and code == 1 and len(problems) == 3
    shutil.rmtree(root, ignore_errors=True)
    print("spdx_headers selftest:", "PASSED" if ok else "FAILED")
    return 0 if ok else 1


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("check", "apply", "selftest"):
        print(__doc__, file=sys.stderr)
        return 2
    mode, root = sys.argv[1], sys.argv[2]
    if mode == "selftest":
        return selftest(root)
    problems, added, checked = [], [], 0
    for path in tracked_files(root):
        if not in_scope(path):
            continue
        checked += 1
        full = os.path.join(root, path)
        with open(full, "rb") as f:
            data = f.read()
        text = data.decode("utf-8")
        lines = text.splitlines(keepends=True)
        want = licence_of(path)
        at = insertion_index(lines)
        found = [(i, m.group(1)) for i, line in enumerate(lines[:at + 3]) for m in [SPDX_RE.search(line)] if m]
        if found:
            i, have = found[0]
            if have != want:
                problems.append(f"{path}:{i + 1}: SPDX-License-Identifier {have}, expected {want}")
            elif i != at:
                problems.append(f"{path}:{i + 1}: SPDX line should be line {at + 1}")
            continue
        if mode == "check":
            problems.append(f"{path}: no SPDX-License-Identifier line (expected: {header_line(style_of(path), want)})")
            continue
        newline = "\r\n" if lines and lines[0].endswith("\r\n") else "\n"
        if at == 1 and not lines[0].endswith("\n"):
            lines[0] += newline
        lines.insert(at, header_line(style_of(path), want) + newline)
        with open(full, "wb") as f:
            f.write("".join(lines).encode("utf-8"))
        added.append(path)
    for p in problems:
        print(p)
    if mode == "apply":
        print(f"spdx_headers: {len(added)} header(s) added, {checked} files in scope")
    else:
        print(f"spdx_headers: {checked} files checked, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
