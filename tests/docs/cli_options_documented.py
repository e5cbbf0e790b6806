#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Every option of the aggrelod CLI is documented exactly once, where its help says.

    cli_options_documented.py check CLI REPO_ROOT   compares `CLI SUB --help` with the docs
    cli_options_documented.py selftest TMP_DIR      the check finds planted problems

The reference is docs/command-line.md: one section per subcommand headed "## `aggrelod SUB`",
and in it one bullet per option, "- `--name ARG`" or "- `-o, --name ARG`". The check asks
that every option the CLI's help lists (but -h/--help) has exactly one bullet in its section,
with the same short form, that no bullet names an option the CLI does not have, and that no
other Markdown file of the repository defines options again (such bullets, or an option list
in a code block: "  --name ARG   description").
Exit status: 0 when all is well, 1 with one line per problem otherwise.
"""
import os
import re
import subprocess
import sys

REFERENCE = os.path.join("docs", "command-line.md")
HELP_OPTION = re.compile(r"^\s{2}(?:-(\w),)?--([A-Za-z0-9][\w-]*)")
DOC_SECTION = re.compile(r"^## `aggrelod ([\w-]+)`\s*$")
DOC_BULLET = re.compile(r"^- `(?:-(\w), )?--([A-Za-z0-9][\w-]*)")
# An option list in a code block: the option, maybe one argument word, then a gap and text.
CODE_LIST_LINE = re.compile(r"^\s{2,}(?:-\w, )?--[A-Za-z0-9][\w-]*(?: \S+)?\s{2,}\S")
SKIP_DIRS = {".git", "build", "node_modules", "tmp", "out"}


def run_help(cli, args):
    r = subprocess.run([cli] + args + ["--help"], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join([cli] + args)} --help exited with {r.returncode}: {r.stderr.strip()}")
    return r.stdout


def subcommands(cli):
    names, inside = [], False
    for line in run_help(cli, []).splitlines():
        if line.startswith("Subcommands:"):
            inside = True
        elif inside and line.strip():
            m = re.match(r"^\s{2}([\w-]+)\s", line)
            if m:
                names.append(m.group(1))
        elif inside and not line.strip() and names:
            break
    return names


def help_options(cli, sub):
    """{long name: short letter or None} of one subcommand, without --help."""
    options = {}
    for line in run_help(cli, [sub]).splitlines():
        m = HELP_OPTION.match(line)
        if m and m.group(2) != "help":
            options[m.group(2)] = m.group(1)
    return options


def doc_sections(text):
    """{subcommand: [(long, short, line number)]} of the bullets in each section."""
    sections, current, fenced = {}, None, False
    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            continue
        m = DOC_SECTION.match(line)
        if m:
            current = m.group(1)
            sections.setdefault(current, [])
            continue
        if line.startswith("## "):
            current = None
            continue
        b = DOC_BULLET.match(line)
        if b and current is not None:
            sections[current].append((b.group(2), b.group(1), number))
    return sections


def markdown_files(root):
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("build"))
        for f in sorted(files):
            if f.endswith(".md"):
                yield os.path.join(folder, f)


def repeated_definitions(path, rel, known):
    """Lines of a Markdown file other than the reference that define an option again."""
    problems, fenced = [], False
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if line.startswith("```"):
                fenced = not fenced
                continue
            b = DOC_BULLET.match(line)
            if b and not fenced and b.group(2) in known:
                problems.append(f"{rel}:{number}: defines --{b.group(2)} again (its place is {REFERENCE})")
            if fenced and CODE_LIST_LINE.match(line):
                name = re.search(r"--([A-Za-z0-9][\w-]*)", line).group(1)
                if name in known:
                    problems.append(f"{rel}:{number}: lists --{name} in a code block (its place is {REFERENCE})")
    return problems


def check(cli, root):
    problems = []
    reference = os.path.join(root, REFERENCE)
    if not os.path.isfile(reference):
        return [f"{REFERENCE} is missing"]
    with open(reference, encoding="utf-8") as f:
        sections = doc_sections(f.read())
    subs = subcommands(cli)
    if not subs:
        problems.append(f"{cli} --help lists no subcommands")
    known = set()
    for sub in subs:
        options = help_options(cli, sub)
        known.update(options)
        if sub not in sections:
            problems.append(f"{REFERENCE}: no section \"## `aggrelod {sub}`\"")
            continue
        seen = {}
        for name, short, number in sections[sub]:
            seen.setdefault(name, []).append((short, number))
        for name, short in sorted(options.items()):
            uses = seen.get(name, [])
            if not uses:
                problems.append(f"{REFERENCE}: aggrelod {sub} --{name} is not documented")
            elif len(uses) > 1:
                lines = ", ".join(str(n) for _, n in uses)
                problems.append(f"{REFERENCE}: aggrelod {sub} --{name} is documented {len(uses)} times (lines {lines})")
            elif uses[0][0] != short:
                problems.append(f"{REFERENCE}:{uses[0][1]}: aggrelod {sub} --{name}: short form "
                                f"{'-' + uses[0][0] if uses[0][0] else 'none'} in the docs, "
                                f"{'-' + short if short else 'none'} in the help")
        for name, uses in sorted(seen.items()):
            if name not in options:
                problems.append(f"{REFERENCE}:{uses[0][1]}: aggrelod {sub} has no option --{name}")
    for sub in sorted(set(sections) - set(subs)):
        problems.append(f"{REFERENCE}: section for aggrelod {sub}, which the CLI does not have")
    for path in markdown_files(root):
        rel = os.path.relpath(path, root)
        if rel != REFERENCE:
            problems += repeated_definitions(path, rel, known)
    return problems


FAKE_CLI = r"""#!/bin/sh
if [ "$1" = "--help" ]; then
  printf 'fake\nUsage: fake [OPTIONS] SUBCOMMAND\n\nSubcommands:\n  bake   Bake\n  plan   Plan\n'
elif [ "$1" = "bake" ]; then
  printf 'Bake\nOptions:\n  -h,--help  Help\n  -o,--output TEXT  Out\n  --levels INT  Levels\n  --stats TEXT  Stats\n'
else
  printf 'Plan\nOptions:\n  -h,--help  Help\n  --radius FLOAT  Radius\n'
fi
"""

GOOD_DOC = """# CLI

## `aggrelod bake`

### Options

- `-o, --output DIR` — where
- `--levels N` — how many
- `--stats FILE` — figures

## `aggrelod plan`

### Options

- `--radius R` — agent radius
"""


def selftest(tmp):
    root = os.path.join(tmp, "cli_options_documented_selftest")
    os.makedirs(os.path.join(root, "docs"), exist_ok=True)
    cli = os.path.join(root, "fake-cli")
    with open(cli, "w") as f:
        f.write(FAKE_CLI)
    os.chmod(cli, 0o755)
    extra = os.path.join(root, "docs", "other.md")

    def problems_with(doc, other=""):
        with open(os.path.join(root, REFERENCE), "w") as f:
            f.write(doc)
        with open(extra, "w") as f:
            f.write(other)
        return check(cli, root)

    cases = [
        ("clean docs", GOOD_DOC, "", None),
        ("missing option", GOOD_DOC.replace("- `--levels N` — how many\n", ""), "", "--levels is not documented"),
        ("twice", GOOD_DOC + "\n## `aggrelod plan`\n\n- `--radius R` — again\n", "", "documented 2 times"),
        ("unknown option", GOOD_DOC.replace("--stats FILE", "--statz FILE"), "", "has no option --statz"),
        ("short form", GOOD_DOC.replace("-o, --output", "--output"), "", "short form"),
        ("missing section", GOOD_DOC.split("## `aggrelod plan`")[0], "", "no section"),
        ("bullet elsewhere", GOOD_DOC, "- `--levels 3` — again\n", "defines --levels again"),
        ("code list elsewhere", GOOD_DOC, "```\n  --stats FILE    write figures\n```\n", "lists --stats in a code block"),
    ]
    failures = []
    for label, doc, other, expected in cases:
        found = problems_with(doc, other)
        if expected is None and found:
            failures.append(f"{label}: unexpected problems {found}")
        if expected is not None and not any(expected in p for p in found):
            failures.append(f"{label}: expected a problem containing '{expected}', got {found}")
    return failures


def main(argv):
    if len(argv) == 4 and argv[1] == "check":
        problems = check(argv[2], argv[3])
        for p in problems:
            print(p)
        print(f"cli_options_documented: {'PASSED' if not problems else 'FAILED'}")
        return 0 if not problems else 1
    if len(argv) == 3 and argv[1] == "selftest":
        failures = selftest(argv[2])
        for f in failures:
            print(f)
        print(f"cli_options_documented selftest: {'PASSED' if not failures else 'FAILED'}")
        return 0 if not failures else 1
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
