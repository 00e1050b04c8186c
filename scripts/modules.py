"""scripts/modules.py - src/MODULES, read once for scripts/layering and
scripts/layout (imported by both; not a program).

src/MODULES lists the library's modules in order, one line each (the
module, then the stems of files that belong to it besides its own), under
section lines `[LAYER]`: a layer is the folder src/LAYER/ that holds the
files of its modules, and the layers come in the order of the modules.
"""
import os, re

# Folders of src/ that are not layers: the C++ adapters, the tools' shared
# code and the tools. They stay where they are.
FIXED = ('adapters', 'cli', 'tools')
HEADING = re.compile(r'\[([a-z][a-z0-9_]*)\]$')


class Modules:
    """order: the modules in order; owner: extra file stem -> module;
    layer: module -> its layer (None before the first heading); layers: the
    layers in order; errors: 'src/MODULES:LINE: ...' for bad lines."""

    def __init__(self, root):
        self.order, self.owner, self.layer = [], {}, {}
        self.layers, self.errors = [], []
        current = None
        with open(os.path.join(root, 'src', 'MODULES')) as f:
            for no, line in enumerate(f, 1):
                text = line.split('#', 1)[0].strip()
                if not text:
                    continue
                h = HEADING.match(text)
                if h:
                    name = h.group(1)
                    if name in FIXED or name in self.layers:
                        self.errors.append(
                            'src/MODULES:%d: layer [%s] %s' % (no, name,
                            'is a fixed folder of src/' if name in FIXED else
                            'comes twice (a layer is one run of modules)'))
                    else:
                        self.layers.append(name)
                    current = name
                    continue
                words = text.split()
                if words[0] in self.layer:
                    self.errors.append('src/MODULES:%d: module %s comes twice'
                                       % (no, words[0]))
                self.order.append(words[0])
                self.layer[words[0]] = current
                for extra in words[1:]:
                    self.owner[extra] = words[0]
        self.pos = {m: i for i, m in enumerate(self.order)}

    def module(self, name):
        """The module of a file (path or name): its stem listed as an extra,
        the stem itself, else the longest listed NAME_ prefix (vtk_capture
        before vtk); the stem when none is listed."""
        stem = os.path.basename(name).rsplit('.', 1)[0]
        if stem in self.owner:
            return self.owner[stem]
        if stem in self.pos:
            return stem
        parts = stem.split('_')
        for k in range(len(parts) - 1, 0, -1):
            if '_'.join(parts[:k]) in self.pos:
                return '_'.join(parts[:k])
        return stem


def library_files(root):
    """The library's files under src/, relative to root: src/* and
    src/DIR/* for every DIR but the fixed ones (flat or laid out), and
    src/adapters/*.  src/MODULES is not one."""
    out = []
    src = os.path.join(root, 'src')
    for name in sorted(os.listdir(src)):
        path = os.path.join(src, name)
        if os.path.isfile(path):
            if name != 'MODULES':
                out.append('src/' + name)
        elif os.path.isdir(path) and name not in ('cli', 'tools'):
            for sub in sorted(os.listdir(path)):
                if os.path.isfile(os.path.join(path, sub)):
                    out.append('src/%s/%s' % (name, sub))
    return out
