#!/usr/bin/python3
# tests/tools/gltf_assets.py DIR - write the glTF 2.0 test assets of
# tests/tools/gltf.t into DIR, each valid one with NAME.expect.obj: the soup
# the reader must give (world-space vertices in node order, triangles in
# primitive order), computed here independently of the C reader. Invalid
# assets are listed in DIR/invalid.txt as "FILE<TAB>regex of the message".
#
# Assets: TRIANGLES with u16 indices in an external .bin whose name needs
# percent-decoding; the same with a base64 data URI; a .glb with a
# TRIANGLE_STRIP (non-indexed), a TRIANGLE_FAN (u8 indices) and a POINTS
# primitive (ignored, warned); a node hierarchy with a matrix root, TRS
# children (a non-unit quaternion), a mesh instanced twice, and a second
# scene the default scene leaves out; no "scene" (every root node);
# KHR_mesh_quantization positions (normalized i16, plain u8) with u32
# indices; sparse accessors (over a buffer view and over zeros); an
# interleaved vertex buffer (byteStride 24).
import base64, json, math, os, struct, sys

import numpy as np

D = sys.argv[1]
os.makedirs(D, exist_ok=True)
FMT = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}
NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


class Doc:
    def __init__(self):
        self.bin = bytearray()
        self.j = {"asset": {"version": "2.0", "generator": "souptet tests"},
                  "buffers": [], "bufferViews": [], "accessors": [],
                  "meshes": [], "nodes": [], "scenes": []}

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        self.bin += data
        self.j["bufferViews"].append(v)
        return len(self.j["bufferViews"]) - 1

    def accessor(self, values, ctype, typ, normalized=False):
        flat = [x for row in values for x in (row if isinstance(row, (list, tuple)) else [row])]
        data = struct.pack("<%d%s" % (len(flat), FMT[ctype]), *flat)
        a = {"bufferView": self.view(data), "componentType": ctype,
             "count": len(values), "type": typ}
        if normalized:
            a["normalized"] = True
        self.j["accessors"].append(a)
        return len(self.j["accessors"]) - 1

    def raw_accessor(self, a):
        self.j["accessors"].append(a)
        return len(self.j["accessors"]) - 1

    def mesh(self, prims):
        self.j["meshes"].append({"primitives": prims})
        return len(self.j["meshes"]) - 1

    def node(self, **kw):
        self.j["nodes"].append(kw)
        return len(self.j["nodes"]) - 1

    def finish(self, uri=None):
        self.j["buffers"] = [{"byteLength": len(self.bin)}]
        if uri:
            self.j["buffers"][0]["uri"] = uri
        return self.j

    def write_gltf(self, name, binname="%s.bin", uri=None, datauri=False):
        if datauri:
            u = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.bin)).decode()
            j = self.finish(u)
        else:
            fn = binname % name if "%s" in binname else binname
            with open(os.path.join(D, fn), "wb") as f:
                f.write(self.bin)
            j = self.finish(uri or fn)
        with open(os.path.join(D, name + ".gltf"), "w") as f:
            json.dump(j, f, indent=1)

    def write_glb(self, name):
        j = self.finish()
        js = json.dumps(j).encode()
        while len(js) % 4:
            js += b" "
        b = bytes(self.bin)
        while len(b) % 4:
            b += b"\0"
        out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(b))
        out += struct.pack("<II", len(js), 0x4E4F534A) + js
        out += struct.pack("<II", len(b), 0x004E4942) + b
        with open(os.path.join(D, name + ".glb"), "wb") as f:
            f.write(out)


# ---- expected soups -----------------------------------------------------
def trs(t=(0, 0, 0), r=(0, 0, 0, 1), s=(1, 1, 1)):
    x, y, z, w = r
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    M = np.eye(4)
    M[:3, :3] = R @ np.diag(s)
    M[:3, 3] = t
    return M


def from_colmajor(m):
    return np.array(m, dtype=float).reshape(4, 4).T


def tris_of(mode, n, idx=None):
    k = list(range(n)) if idx is None else list(idx)
    if mode == 4:
        return [(k[i], k[i + 1], k[i + 2]) for i in range(0, len(k), 3)]
    if mode == 5:
        return [((k[i], k[i + 1], k[i + 2]) if i % 2 == 0 else (k[i + 1], k[i], k[i + 2]))
                for i in range(len(k) - 2)]
    if mode == 6:
        return [(k[i + 1], k[i + 2], k[0]) for i in range(len(k) - 2)]
    return []


class Expect:
    def __init__(self):
        self.v, self.t = [], []

    def add(self, M, pos, mode, idx=None):
        base = len(self.v)
        for p in pos:
            q = M @ np.array([p[0], p[1], p[2], 1.0])
            self.v.append(q[:3])
        for a, b, c in tris_of(mode, len(pos), idx):
            self.t.append((base + a, base + b, base + c))

    def write(self, name):
        with open(os.path.join(D, name + ".expect.obj"), "w") as f:
            for p in self.v:
                f.write("v %r %r %r\n" % (float(p[0]), float(p[1]), float(p[2])))
            for a, b, c in self.t:
                f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


def f32(rows):
    return [[float(np.float32(x)) for x in r] for r in rows]


QUAD = f32([[0, 0, 0], [1.5, 0, 0], [1.5, 1, 0.25], [0, 1, 0.1]])
QIDX = [0, 1, 2, 0, 2, 3]

# ---- tri: external .bin named "my mesh.bin" (uri percent-encoded) --------
d = Doc()
pa = d.accessor(QUAD, 5126, "VEC3")
ia = d.accessor(QIDX, 5123, "SCALAR")
m = d.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
d.j["scene"] = 0
d.write_gltf("tri", binname="my mesh.bin", uri="my%20mesh.bin")
e = Expect(); e.add(np.eye(4), QUAD, 4, QIDX); e.write("tri")

# ---- datauri: the same, buffer inline -----------------------------------
d = Doc()
pa = d.accessor(QUAD, 5126, "VEC3")
ia = d.accessor(QIDX, 5123, "SCALAR")
m = d.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
d.write_gltf("datauri", datauri=True)
e = Expect(); e.add(np.eye(4), QUAD, 4, QIDX); e.write("datauri")

# ---- strips.glb: strip, fan, points -------------------------------------
STRIP = f32([[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0.5], [2, 0, 0], [2, 1, 1]])
FAN = f32([[0, 0, 2], [1, 0, 2], [1, 1, 2], [0, 1, 2.5], [-1, 0.5, 2]])
FIDX = [0, 1, 2, 3, 4]
d = Doc()
sa = d.accessor(STRIP, 5126, "VEC3")
fa = d.accessor(FAN, 5126, "VEC3")
fi = d.accessor(FIDX, 5121, "SCALAR")
m = d.mesh([{"attributes": {"POSITION": sa}, "mode": 5},
            {"attributes": {"POSITION": fa}, "indices": fi, "mode": 6},
            {"attributes": {"POSITION": sa}, "mode": 0}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m, translation=[0, 0, -1])]}]
d.write_glb("strips")
e = Expect(); T = trs(t=(0, 0, -1))
e.add(T, STRIP, 5); e.add(T, FAN, 6, FIDX); e.write("strips")

# ---- nodes: matrix root, TRS children, a mesh twice, a scene left out ----
TET = f32([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TIDX = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]
d = Doc()
pa = d.accessor(TET, 5126, "VEC3")
ia = d.accessor(TIDX, 5125, "SCALAR")
m = d.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
c = math.cos(0.3); s_ = math.sin(0.3)
root_m = [2 * c, 2 * s_, 0, 0, -2 * s_, 2 * c, 0, 0, 0, 0, 2, 0, 5, -1, 3, 1]  # column-major
gchild = d.node(mesh=m, scale=[1, 2, 0.5], translation=[0, 0, 1])
child1 = d.node(mesh=m, translation=[1, 2, 3], rotation=[0.2, 0.4, 0.1, 0.9],
                children=[gchild])
child2 = d.node(rotation=[0, 0.7071068, 0, 0.7071068], scale=[3, 3, 3], mesh=m)
root = d.node(matrix=root_m, children=[child1, child2])
other = d.node(mesh=m, translation=[100, 0, 0])
d.j["scenes"] = [{"nodes": [other]}, {"nodes": [root]}]
d.j["scene"] = 1
d.write_gltf("nodes")
R = from_colmajor(root_m)
C1 = R @ trs(t=(1, 2, 3), r=(0.2, 0.4, 0.1, 0.9))
G = C1 @ trs(t=(0, 0, 1), s=(1, 2, 0.5))
C2 = R @ trs(r=(0, float(np.float64(0.7071068)), 0, 0.7071068), s=(3, 3, 3))
e = Expect()
for M in (C1, G, C2):   # depth first, children in order
    e.add(M, TET, 4, TIDX)
e.write("nodes")

# ---- noscene: no "scene": every root node, in node order ----------------
d = Doc()
pa = d.accessor(TET, 5126, "VEC3")
m = d.mesh([{"attributes": {"POSITION": pa}, "indices": d.accessor(TIDX, 5121, "SCALAR")}])
n1 = d.node(mesh=m, translation=[0, 0, 5])
r1 = d.node(mesh=m, children=[n1])
r2 = d.node(mesh=m, translation=[-3, 0, 0])
d.j.pop("scenes")
d.write_gltf("noscene")
e = Expect()
e.add(np.eye(4), TET, 4, TIDX); e.add(trs(t=(0, 0, 5)), TET, 4, TIDX)
e.add(trs(t=(-3, 0, 0)), TET, 4, TIDX)
e.write("noscene")

# ---- quant: KHR_mesh_quantization --------------------------------------
QS = [[-32767, 0, 32767], [32767, -32768, 0], [0, 16384, -16384]]
QB = [[0, 0, 0], [255, 0, 0], [0, 200, 10]]
d = Doc()
qa = d.accessor(QS, 5122, "VEC3", normalized=True)
ba = d.accessor(QB, 5121, "VEC3")
m = d.mesh([{"attributes": {"POSITION": qa}, "indices": d.accessor([0, 1, 2], 5125, "SCALAR")},
            {"attributes": {"POSITION": ba}}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
d.j["extensionsUsed"] = ["KHR_mesh_quantization"]
d.j["extensionsRequired"] = ["KHR_mesh_quantization"]
d.write_gltf("quant")
e = Expect()
e.add(np.eye(4), [[max(x / 32767.0, -1.0) for x in r] for r in QS], 4, [0, 1, 2])
e.add(np.eye(4), [[float(x) for x in r] for r in QB], 4)
e.write("quant")

# ---- sparse: over a buffer view, and over zeros -------------------------
d = Doc()
base = d.accessor(QUAD, 5126, "VEC3")
si = d.view(struct.pack("<HH", 1, 3))
sv = d.view(struct.pack("<6f", 9, 9, 9, -1, -2, -3))
d.j["accessors"][base]["sparse"] = {"count": 2, "indices": {"bufferView": si, "componentType": 5123},
                                    "values": {"bufferView": sv}}
zi = d.view(struct.pack("<B", 2))
zv = d.view(struct.pack("<3f", 1, 1, 1))
zero = d.raw_accessor({"componentType": 5126, "count": 3, "type": "VEC3",
                       "sparse": {"count": 1, "indices": {"bufferView": zi, "componentType": 5121},
                                  "values": {"bufferView": zv}}})
m = d.mesh([{"attributes": {"POSITION": base}, "indices": d.accessor(QIDX, 5123, "SCALAR")},
            {"attributes": {"POSITION": zero}}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
d.write_gltf("sparse")
SP = [list(r) for r in QUAD]; SP[1] = [9.0, 9.0, 9.0]; SP[3] = [-1.0, -2.0, -3.0]
e = Expect(); e.add(np.eye(4), SP, 4, QIDX); e.add(np.eye(4), [[0, 0, 0], [0, 0, 0], [1, 1, 1]], 4)
e.write("sparse")

# ---- interleaved: position + normal, byteStride 24 ----------------------
d = Doc()
inter = b"".join(struct.pack("<6f", *p, 0, 0, 1) for p in QUAD)
v = d.view(inter, stride=24)
pa = d.raw_accessor({"bufferView": v, "componentType": 5126, "count": 4, "type": "VEC3"})
na = d.raw_accessor({"bufferView": v, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"})
m = d.mesh([{"attributes": {"POSITION": pa, "NORMAL": na}, "indices": d.accessor(QIDX, 5123, "SCALAR")}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
d.write_glb("interleaved")
e = Expect(); e.add(np.eye(4), QUAD, 4, QIDX); e.write("interleaved")

# ---- invalid assets -------------------------------------------------------
invalid = []


def bad(name, j, regex, binary=None):
    """j: a dict (written as NAME.gltf) or bytes (written as NAME)."""
    if isinstance(j, dict):
        fn = name + ".gltf"
        with open(os.path.join(D, fn), "w") as f:
            json.dump(j, f)
    else:
        fn = name
        with open(os.path.join(D, fn), "wb") as f:
            f.write(j)
    invalid.append((fn, regex))


def good_tri(**over):
    d = Doc()
    pa = d.accessor(QUAD, 5126, "VEC3")
    ia = d.accessor(QIDX, 5123, "SCALAR")
    m = d.mesh([{"attributes": {"POSITION": pa}, "indices": ia}])
    d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
    d.j["scene"] = 0
    return d


def datauri_json(d):
    u = "data:application/octet-stream;base64," + base64.b64encode(bytes(d.bin)).decode()
    return d.finish(u)


d = good_tri(); j = d.finish("missing.bin")
bad("missing-bin", j, r"/buffers/0: cannot open '.*missing\.bin': No such file")
bad("syntax.gltf", b'{"asset": {"version": "2.0"}, "nodes": [1, 2,]}', r"byte 45: JSON: unexpected character")
bad("deep.gltf", b"[" * 100 + b"]" * 100, r"JSON: nested more than 64 deep")
bad("string.gltf", b'{"asset": {"version": "2.0\n"}}', r"JSON: control character")
d = good_tri(); j = datauri_json(d); j["accessors"][0]["count"] = 5
bad("acc-past-view", j, r"/accessors/0: 5 elements of 12 bytes from byte 0 do not fit in buffer view 0")
d = good_tri(); j = datauri_json(d); j["bufferViews"][1]["byteLength"] = 4000
bad("view-past-buffer", j, r"/bufferViews/1: bytes .* past the .* of buffer 0")
d = good_tri(); j = datauri_json(d); j["buffers"][0]["byteLength"] += 8
bad("short-datauri", j, r"/buffers/0: its data URI holds 60 bytes, byteLength says 68")
d = Doc(); pa = d.accessor(QUAD, 5126, "VEC3"); ia = d.accessor([0, 1, 4], 5123, "SCALAR")
m = d.mesh([{"attributes": {"POSITION": pa}, "indices": ia}]); d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
bad("index-range", datauri_json(d), r"/accessors/1: index 4 \(entry 2\) out of range \(POSITION has 4\)")
d = Doc(); pa = d.accessor([[0, 0, 0], [1, float("nan"), 0], [0, 1, 0]], 5126, "VEC3")
m = d.mesh([{"attributes": {"POSITION": pa}}]); d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
bad("nan", datauri_json(d), r"/accessors/0: position 1 is not finite")
d = Doc(); pa = d.accessor([[0, 0, 0], [1e38, 0, 0], [0, 1, 0]], 5126, "VEC3")
m = d.mesh([{"attributes": {"POSITION": pa}}]); d.j["scenes"] = [{"nodes": [d.node(mesh=m, scale=[1e300, 1, 1])]}]
bad("overflow", datauri_json(d), r"/accessors/0: position 1 is not finite .* in world space")
d = good_tri(); j = datauri_json(d)
j["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
bad("cycle", j, r"/nodes/1/children/0: node 0 reached twice \(a cycle")
d = good_tri(); j = datauri_json(d); j.pop("scene"); j.pop("scenes")
j["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
bad("cycle-noroot", j, r"/nodes: every node is a child")
d = good_tri(); j = datauri_json(d)
j["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]; j["scenes"] = [{"nodes": [0, 1]}]
bad("two-parents", j, r"/nodes/1/children/0: node 2 reached twice")
d = good_tri(); j = datauri_json(d); j["extensionsRequired"] = ["KHR_draco_mesh_compression"]
bad("draco", j, r"/extensionsRequired/0: Draco-compressed \(KHR_draco_mesh_compression\)")
d = good_tri(); j = datauri_json(d)
j["meshes"][0]["primitives"][0]["extensions"] = {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}
bad("draco-prim", j, r"/meshes/0/primitives/0: Draco-compressed")
d = Doc(); pa = d.accessor(QUAD, 5126, "VEC3")
m = d.mesh([{"attributes": {"POSITION": pa}, "mode": 0}, {"attributes": {"POSITION": pa}, "mode": 1}])
d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
bad("points-only", datauri_json(d), r"no triangles \(2 point or line primitives ignored\)")
d = good_tri(); j = datauri_json(d); j["asset"]["version"] = "1.0"
bad("version1", j, r"/asset/version: \"1\.0\" \(only glTF 2\.x")
d = good_tri(); j = datauri_json(d); j["accessors"][0].pop("bufferView"); j["accessors"][0]["count"] = 10 ** 9
bad("zeros-huge", j, r"/accessors/0: 1000000000 elements without a buffer view, more than the input's")
d = good_tri(); bi = d.view(struct.pack("<HH", 2, 1)); bv = d.view(struct.pack("<6f", 0, 0, 0, 0, 0, 0))
d.j["accessors"][0]["sparse"] = {"count": 2, "indices": {"bufferView": bi, "componentType": 5123}, "values": {"bufferView": bv}}
bad("sparse-order", datauri_json(d), r"/accessors/0/sparse/indices: index 1 \(entry 1\) is not above the one before")
d = Doc(); pa = d.accessor(QUAD, 5126, "VEC3"); ia = d.accessor([0, 1, 2, 3], 5123, "SCALAR")
m = d.mesh([{"attributes": {"POSITION": pa}, "indices": ia}]); d.j["scenes"] = [{"nodes": [d.node(mesh=m)]}]
bad("not-three", datauri_json(d), r"/meshes/0/primitives/0: 4 TRIANGLES vertices, not a multiple of 3")
d = good_tri(); j = datauri_json(d); j["bufferViews"][0]["byteStride"] = 6
bad("stride", j, r"/bufferViews/0/byteStride: 6")
d = good_tri(); j = datauri_json(d); j["accessors"][0]["componentType"] = 5124
bad("ctype", j, r"/accessors/0/componentType: 5124 is not a glTF component type")
d = good_tri(); j = datauri_json(d); j["buffers"][0]["uri"] = "http://example.com/x.bin"
bad("remote", j, r"only data: URIs and relative file names are read")
d = good_tri(); j = datauri_json(d); j["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAA*"
bad("base64", j, r"/buffers/0/uri: bad base64 at character 3")
# A .glb cut short, and one whose JSON chunk runs past its length.
d = good_tri(); d.write_glb("cut-src")
with open(os.path.join(D, "cut-src.glb"), "rb") as f:
    glb = f.read()
os.remove(os.path.join(D, "cut-src.glb"))
bad("cut.glb", glb[:len(glb) - 10], r"byte 8: GLB length [0-9]+, the file has [0-9]+ bytes \(truncated")
bad("chunk.glb", glb[:12] + struct.pack("<I", 10 ** 6) + glb[16:], r"byte 12: GLB: JSON chunk of 1000000 bytes past the end")
jl = struct.unpack("<I", glb[12:16])[0]
chunk = glb[12:20 + jl]
bad("glb-nobin.glb", struct.pack("<III", 0x46546C67, 2, 12 + len(chunk)) + chunk,
    r"/buffers/0: no uri \(and no GLB binary chunk\)")

with open(os.path.join(D, "invalid.txt"), "w") as f:
    for fn, rx in invalid:
        f.write("%s\t%s\n" % (fn, rx))
