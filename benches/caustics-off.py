#!/usr/bin/env python3
"""Writes a copy of a scene file with its caustics off: `[render] caustics =
false` (the key replaced where the file sets it, added to its `[render]`
table or in a new one).

Usage: benches/caustics-off.py SCENE.toml COPY.toml
"""
import re
import sys

t = open(sys.argv[1]).read()
if re.search(r'^caustics\s*=', t, re.M):
    t = re.sub(r'^caustics\s*=.*$', 'caustics = false', t, flags=re.M)
elif '[render]' in t:
    t = t.replace('[render]', '[render]\ncaustics = false', 1)
else:
    t += '\n[render]\ncaustics = false\n'
open(sys.argv[2], 'w').write(t)
