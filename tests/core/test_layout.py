#!/usr/bin/env python3
"""The layout docs/architecture.md promises, checked on the sources: every #include between our
folders runs the one way the table allows (core <- results <- model <- devices; results <-
stimuli; all <- calib <- studies <- cli; results/csflut includes nothing of ours), and no function
of the product (outside tests/, bench/, examples/) is longer than 100 lines, counted from its
opening brace at column 0 to its closing one. Each finding names the file and line."""
import os
import re
import sys

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..')
MAX_LINES = 100
BELOW = ['core', 'results', 'model', 'devices', 'stimuli', 'calib', 'studies', 'cli']
ALLOWED = {
    'core': set(),
    'results/csflut': set(),
    'results/store': {'core'},
    'results': {'core', 'results/store', 'results/csflut'},
    'model': {'core', 'results', 'results/store', 'results/csflut'},
    'devices': {'core', 'results', 'results/store', 'results/csflut', 'model'},
    'stimuli': {'core', 'results', 'results/store', 'results/csflut'},
    'calib': {'core', 'results', 'results/store', 'results/csflut', 'model', 'devices', 'stimuli'},
    'studies': {'core', 'results', 'results/store', 'results/csflut', 'model', 'devices', 'stimuli',
                'calib'},
    'cli': {'core', 'results', 'results/store', 'results/csflut', 'model', 'devices', 'stimuli',
            'calib', 'studies'},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SIGNATURE_END = re.compile(r'^[A-Za-z_].*\)\s*$')


def folder_of(rel):
    for sub in ('results/csflut', 'results/store'):
        if rel.startswith(sub + '/'):
            return sub
    top = rel.split('/')[0]
    return top if top in ALLOWED else None


def sources():
    for top in BELOW:
        for dirpath, _, names in os.walk(os.path.join(ROOT, top)):
            for n in names:
                if n.endswith(('.c', '.h', '.cpp')):
                    full = os.path.join(dirpath, n)
                    yield os.path.relpath(full, ROOT), full


def include_findings(rel, text):
    own = folder_of(rel)
    for m in INCLUDE.finditer(text):
        target = m.group(1)
        if '/' not in target:
            continue
        other = folder_of(target)
        if other is None or other == own:
            continue
        if other not in ALLOWED[own]:
            line = text.count('\n', 0, m.start()) + 1
            yield f'{rel}:{line}: includes {target}: {own}/ may not include from {other}/'


def long_functions(rel, text):
    lines = text.split('\n')
    start = None
    for i, line in enumerate(lines):
        if line == '{' and i > 0 and (SIGNATURE_END.match(lines[i - 1]) or lines[i - 1].startswith(' ')):
            start = i
        elif line == '}' and start is not None:
            n = i - start + 1
            if n > MAX_LINES:
                yield f'{rel}:{start + 1}: a function of {n} lines (at most {MAX_LINES})'
            start = None


def main():
    findings, n_files = [], 0
    for rel, full in sources():
        with open(full, encoding='utf-8', errors='replace') as f:
            text = f.read()
        n_files += 1
        findings += list(include_findings(rel, text))
        if rel.endswith(('.c', '.cpp')):
            findings += list(long_functions(rel, text))
    for f in findings:
        print(f)
    if n_files < 50:
        print(f'only {n_files} source files found under {ROOT}: wrong root?')
        return 1
    print(f'layout: {n_files} files, {len(findings)} findings')
    return 1 if findings else 0


if __name__ == '__main__':
    sys.exit(main())
