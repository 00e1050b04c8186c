#!/usr/bin/python3
# tests/tools/defaults_check.py - used by docs.t (see below).
import re, subprocess, sys, os
# defaults_check.py DEFAULTS MANDIR: every "tool option value" line of
# DEFAULTS (the library's defaults, test_defaults --print) against the
# "default X" that TOOL --help and man/man1/TOOL.1 give for that option.
mandir = sys.argv[2]
def norm(v):
    v = v.strip().rstrip('.,;:)')
    try:
        return float(v)
    except ValueError:
        return v
def first_default(text):
    m = re.search(r'default:?\s+([^\s;,)]+)', text, re.I)
    if m:
        return norm(m.group(1))
    m = re.search(r'(\S+)\s+\(default\)', text, re.I)
    return norm(m.group(1)) if m else None
def help_block(tool, opt):
    h = subprocess.run([tool, '--help'], capture_output=True, text=True).stdout.splitlines()
    head = re.compile(r'^\s{2,}(?:-\w,\s+)?(-\w|--[\w-]+)\b')
    for i, line in enumerate(h):
        m = head.match(line)
        if m and m.group(1) == opt or re.match(r'^\s{2,}-\w,\s+' + re.escape(opt) + r'\b', line):
            block = [line]
            for l2 in h[i + 1:]:
                if head.match(l2) or not l2.startswith('        '):
                    break
                block.append(l2)
            return ' '.join(block)
    return None
def man_block(tool, opt):
    src = open(os.path.join(mandir, tool + '.1')).read().splitlines()
    ropt = opt.replace('-', r'\-')
    for i, line in enumerate(src):
        if line.startswith('.B') and src[i - 1].startswith('.TP') and \
                re.search(re.escape(ropt) + r'(?![\w\\])', line):
            block = []
            for l2 in src[i + 1:]:
                if l2.startswith('.TP') or l2.startswith('.SH'):
                    break
                block.append(l2)
            t = ' '.join(block)
            t = re.sub(r'\\f.', '', t).replace('\\-', '-').replace('\\(mu', 'x')
            t = re.sub(r'(^|\s)\.\w+\s*', ' ', t)
            return t
    return None
bad = 0
n = 0
for line in open(sys.argv[1]):
    tool, opt, val = line.split()
    want = norm(val)
    for where, block in (('--help', help_block(tool, opt)), ('man', man_block(tool, opt))):
        n += 1
        got = first_default(block) if block else None
        good = got is not None and (got == want or (isinstance(got, float) and isinstance(want, float) and abs(got - want) <= 1e-12 * max(1, abs(want))))
        print('%s %s %s %s: code %s, text %s' % ('ok' if good else 'BAD', tool, opt, where, val, got))
        bad += not good
sys.exit(1 if bad else 0)
