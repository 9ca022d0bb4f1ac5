#!/usr/bin/env python3
"""Counts the branch points (`if`, `match` arms, `else`, `?`-free `&&`/`||` are not counted)
in the body of one function: `branch_points.py FILE FN`. A crude measure of how many flags a
function re-tests: every `if`/`else if` and every `match` arm (`=>`) counts once."""
import re, sys
text = open(sys.argv[1]).read()
m = re.search(r'\bfn ' + re.escape(sys.argv[2]) + r'\b[^{]*\{', text)
if not m:
    sys.exit(f"no fn {sys.argv[2]} in {sys.argv[1]}")
depth, i = 1, m.end()
while depth and i < len(text):
    depth += {'{': 1, '}': -1}.get(text[i], 0)
    i += 1
body = re.sub(r'//[^\n]*', '', text[m.end():i])
ifs = len(re.findall(r'\bif\b', body))
arms = len(re.findall(r'=>', body))
print(f"{sys.argv[2]}: {body.count(chr(10))} lines, {ifs} if, {arms} match arms, {ifs + arms} branch points")
