#!/usr/bin/env python3
"""The man page (docs/csfcal.1) and `--help` agree.

For each command `csfcal --help` lists:
  - every subcommand its summary names appears in the man page's SYNOPSIS;
  - every option its `--help` names (the text above "Common options:") appears in the man page's
    section for that command (the .SS sections whose title starts with the command), or, for a
    common option, under COMMON OPTIONS;
  - every option a .TP entry of that section defines is one its `--help` names (or a common one),
    so the man page cannot keep an option the tool dropped.
Every common option of `--help` appears under COMMON OPTIONS. Fails naming the command and the
option.

    test_man_help.py CSFCAL MANPAGE
"""
import re
import subprocess
import sys

OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*[a-z0-9]|-[a-zA-Z])(?![\w-])")


def groff_text(line):
    """A man page line as text: escaped dashes as dashes, font changes and quotes dropped."""
    line = line.replace("\\-", "-").replace("\\(en", "-").replace("\\(fm", "'")
    line = re.sub(r"\\f[BIRP]", "", line)
    return line.replace('"', "")


def man_sections(path):
    """{'SH title' or 'SS title': [text lines]} and, per section, the options .TP entries define."""
    sections, defined = {}, {}
    cur, after_tp = "", False
    for raw in open(path, encoding="utf-8"):
        raw = raw.rstrip("\n")
        m = re.match(r'^\.(SH|SS)\s+"?([^"]*)"?', raw)
        if m:
            cur = m.group(1) + " " + m.group(2).strip()
            sections.setdefault(cur, [])
            defined.setdefault(cur, set())
            after_tp = False
            continue
        if raw.startswith(".TP"):
            after_tp = True
            continue
        text = groff_text(re.sub(r"^\.(B|BI|BR|I|IR|RB|RI|IP|PP|br|nf|fi)\b\s*", "", raw))
        if after_tp and re.match(r"^\.(B|BI|BR)\b", raw):
            first = OPTION.match(text.strip())
            if first:
                defined[cur].add(first.group(1))
        after_tp = False
        sections.setdefault(cur, []).append(text)
    return sections, defined


def help_text(csfcal, *args):
    p = subprocess.run([csfcal, *args, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    return p.stdout.decode("utf-8", "replace")


def main():
    csfcal, man = sys.argv[1], sys.argv[2]
    sections, defined = man_sections(man)
    common_man = "\n".join(sections.get("SH COMMON OPTIONS", []))
    # one entry per "csfcal ..." form, however the lines are broken
    synopsis = re.split(r"(?=\bcsfcal )", " ".join(sections.get("SH SYNOPSIS", [])))
    problems = []
    top = help_text(csfcal)
    commands = re.findall(r"^  (\w+)\s+\1\b([^:]*):", top, re.M)
    if not commands:
        problems.append("csfcal --help lists no commands")
    common = None
    for cmd, subs in commands:
        text = help_text(csfcal, cmd)
        own, _, common_part = text.partition("Common options:")
        if common is None:
            common = set(OPTION.findall(common_part))
            for opt in sorted(common):
                if not re.search(r"(?<![\w-])" + re.escape(opt) + r"(?![\w-])", common_man):
                    problems.append(f"common option {opt}: in --help, not under COMMON OPTIONS of {man}")
        for sub in re.findall(r"[a-z]+", subs.split()[0] if subs.strip() else ""):
            if not any(re.search(r"\b" + cmd + r"\b.*\b" + sub + r"\b", l) for l in synopsis):
                problems.append(f"{cmd} {sub}: in csfcal --help, not in the man page's SYNOPSIS")
        keys = [k for k in sections if k.startswith("SS ") and k[3:].split()[0] == cmd]
        if not keys:
            problems.append(f"{cmd}: no .SS section for it in {man}")
            continue
        body = "\n".join("\n".join(sections[k]) for k in keys)
        helped = set(OPTION.findall(own))
        for opt in sorted(helped):
            in_body = re.search(r"(?<![\w-])" + re.escape(opt) + r"(?![\w-])", body)
            if not in_body and not (opt in (common or set()) and opt in common_man):
                problems.append(f"{cmd} {opt}: in `csfcal {cmd} --help`, not in the man page's {cmd} section")
        for k in keys:
            for opt in sorted(defined[k] - helped - (common or set())):
                problems.append(f"{cmd} {opt}: the man page's '{k[3:]}' defines it, `csfcal {cmd} --help` does not")
    for p in problems:
        print("FAIL " + p)
    print(f"{len(commands)} commands compared, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
