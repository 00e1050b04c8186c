"""souptet: coarse tetrahedral meshes that provably enclose damaged triangle soups.

    V, F = souptet.read("bunny.obj")
    m = souptet.mesh(V, F, cells=10)
    m.points, m.tets, m.boundary, m.min_dihedral, m.encloses
    m.write("bunny.msh")

The work is done by the C library (libsouptet: needs libgomp, libxxhash,
libjansson and zlib only). wrap() and writing .vtu need libsouptet-io (OpenVDB, VTK), imported
only when called; without it they raise souptet.Error saying so.

Arrays: V float64 (n, 3); F, tets, boundary and embed_tet are int64.
Every call releases the GIL while the library works, and Ctrl-C in the main
thread stops mesh(), pseudo_volume(), distance() and wrap() with
KeyboardInterrupt.
"""

from . import _core
from ._core import Cancel, Cancelled, Error

__all__ = ["read", "mesh", "pseudo_volume", "distance", "wrap", "Error",
           "Cancel", "Cancelled", "MeshResult", "Field"]
__version__ = _core.version


def _load_io():
    try:
        from . import _io as io
    except ImportError as e:
        raise Error("this needs souptet's OpenVDB/VTK part (souptet._io, linking "
                    "libsouptet-io.so, OpenVDB and VTK), which cannot be loaded: %s" % e) from e
    return io


def read(path):
    """Read a triangle soup: .obj .off .ply .stl .gltf .glb (as every souptet tool).

    path: str or os.PathLike; "-" reads stdin (format sniffed).
    Returns (V, F): V float64 (n, 3) vertex coordinates in model units, F int64
    (m, 3) vertex indices, exactly as the file gives them (never welded,
    polygons fan-triangulated). Reader notes become a UserWarning.
    Raises OSError for files that cannot be read, souptet.Error for bad data.
    """
    return _core.read(path)


class MeshResult:
    """What mesh() gives: the chosen candidate's tet mesh.

    points      float64 (n, 3), model units
    tets        int64 (m, 4), indices into points, positively oriented
                (signed volume > 0)
    boundary    int64 (k, 3), the boundary triangles, normals (b-a)x(c-a)
                pointing out of the mesh, indices into points
    min_dihedral, max_dihedral   degrees, over all tets
    encloses    bool: every input vertex inside, no input triangle crossing
                the boundary (checked exactly)
    converged   bool: every boundary vertex within offset * h of the input
    h           float, the lattice cell width in model units
    seed        int, the lattice seed of the chosen candidate
    embed_tet   int64 (len(V),): for each row of V the tet containing it
                (-1: none)
    embed_bary  float64 (len(V), 4): its barycentric coordinates there,
                V[i] = sum(embed_bary[i, c] * points[tets[embed_tet[i], c]])
    guessed     float, the share of the solid's boundary not on the input
                but guessed (hole caps, a one-sided scan's far side)
    parts       int32 (m,) or None: each tet's part (mesh(..., parts=...);
                soupmesh --parts), the part owning most of its volume
    part_share  float64 (m,) or None: the share of the tet that part owns
                (0: the tet covers no part and took the nearest)
    part_names  list of str or None: the parts' names, by index
    seconds     float, the library's wall time
    """

    def __init__(self, d):
        self._mesh = d.pop("_mesh")
        self.__dict__.update(d)

    def __repr__(self):
        return ("<souptet.MeshResult %d points, %d tets, dihedral %.2f..%.2f, h %.6g, %s>"
                % (len(self.points), len(self.tets), self.min_dihedral, self.max_dihedral,
                   self.h, "encloses" if self.encloses else "DOES NOT enclose"))

    def to_meshio(self):
        """The mesh as a meshio.Mesh (cells "tetra"; imports meshio)."""
        import meshio
        return meshio.Mesh(self.points, [("tetra", self.tets)])

    def write(self, path, *, msh_version=41, binary=False):
        """Write the mesh as soupmesh -o does, by the path's extension.

        path         .msh (Gmsh; physical groups volume and boundary, the
                     boundary as outward triangles), .node/.ele (TetGen, both
                     written), .mesh (Medit), .vtu (VTK; needs souptet._io).
                     Coordinates are written exactly (17 digits or raw doubles).
        msh_version  41 (default) or 22, .msh only
        binary       False (default): ASCII .msh; True: binary, .msh only
        """
        import os
        p = os.fspath(path)
        ext = (p.decode() if isinstance(p, bytes) else p).lower()
        if ext.endswith(".vtu"):
            _load_io().write_vtu(self._mesh, p)
        else:
            _core.write(self._mesh, p, msh_version, binary)


def read_parts(path, mode="auto"):
    """Read a surface file with its parts (soupmesh --parts MODE).

    mode   "names" (OBJ objects, or groups without objects; glTF mesh
           nodes; STL solids), "pieces" (edge-connected pieces) or "auto"
           (names where the file has them, else pieces)
    Returns (V, F, part, names): V and F as read() gives them, part int32
    (len(F),) each triangle's part, names a list of str (unique, UTF-8).
    mesh(V, F, parts=part, part_names=names) tags the tets with them.
    """
    return _core.read_parts(path, mode)


def mesh(V, F, *, cells=10, size=None, tets=None, tries=4, seed=1, offset=0.4,
         threads=0, progress=None, float32=False, cancel=None, try_all=False,
         parts=None, part_names=None, fill_holes=True, symmetry=True):
    """Mesh a triangle soup into a coarse tet mesh that encloses it (soupmesh).

    V         (n, 3) numbers, the vertices in model units (finite)
    F         (m, 3) integers, triangles as indices into V (any orientation,
              holes, interpenetrating parts)
    cells     int, BCC lattice cells along the longest side of the model's
              box (default 10, as soupmesh; 1..4096); more cells, more tets
    size      float or None, the lattice cell width h in model units instead
              of cells (soupmesh -h/--size; default None: from cells)
    tets      int or None, choose h for about this many tets, cells or size
              giving the first guess (soupmesh --tets; default None)
    tries     int, candidates with randomly rotated and offset lattices, at
              most, two at a time in parallel, the best enclosing one kept;
              no more start once one meets every goal (encloses, offset,
              dihedral 35..133; soupmesh --tries) (default 4; NOTE:
              soupmesh's default is 1 - here 4, because the worst angle
              improves and a script rarely tunes it; tries=1 gives
              soupmesh's mesh bit for bit)
    seed      int >= 0, the first candidate's lattice seed (default 1;
              0: the axis-aligned lattice)
    offset    float, fit until every boundary vertex is within offset * h
              of the input (cell widths, default 0.4; 0.001..10)
    threads   int, threads to use (default 0: all cores); the result does
              not depend on it
    progress  callable or None: called with a dict per pipeline event:
              what ("field", "size", "sculpted", "iteration", "candidate",
              or "progress" for the stage fraction), k (candidate), h,
              tets, seconds, voxel, field_dims, stage and fraction (the
              library's latest stage and its fraction done, 0..1); for
              "iteration" also phase, iteration, min_dihedral,
              max_dihedral, max_distance. It runs with the GIL held, maybe
              on another thread, never two at once; an exception raised in
              it stops the run and propagates.
    float32   bool, the mesh encloses the input after its points are rounded
              to float32, checked exactly on the rounded points (default
              False; soupmesh --float32): for Blender, glTF, STL, game
              engines, anything that stores float32
    try_all   bool, run all tries candidates even once one meets every goal
              (soupmesh --try-all; default False)
    cancel    souptet.Cancel or None: another thread's c.set() stops the
              run within about 0.1 s of work (the library polls the flag
              itself) and mesh() raises souptet.Cancelled (default None)
    parts     None (default), "pieces" (the soup's edge-connected pieces),
              or an integer array (len(F),) of each triangle's part
              (0..65534; read_parts gives one): each tet gets the part
              owning most of its volume, the inner part where one lies in
              another (.parts, .part_share, .part_names; written by write())
    part_names  list of str or None: the parts' names (default part_K)
    fill_holes  bool, cap the soup's holes for the pseudo volume (default
              True, as soupsign/soupmesh --fill-holes on; False: the vote
              alone closes them)
    symmetry    bool, fill the holes from the soup's own mirror planes,
              rotation axes and helices (a screw's thread), where their
              images close a hole (default
              True, as --symmetry on; needs fill_holes)
    Returns a MeshResult. Not enclosing is not an error: see .encloses.
    Raises souptet.Error for bad input or parameters, MemoryError.
    """
    return MeshResult(_core.mesh(V, F, cells=cells, size=size, tets=tets, tries=tries,
                                 seed=seed, offset=offset, threads=threads,
                                 progress=progress, float32=float32, cancel=cancel,
                                 try_all=try_all, parts=parts, part_names=part_names,
                                 fill_holes=fill_holes, symmetry=symmetry))


class Field:
    """A field on a regular grid of voxels.

    values   float32 (nx, ny, nz), indexed [i, j, k]; voxel (i, j, k) is
             centered at origin + voxel * (i, j, k)
    inside   bool (nx, ny, nz), pseudo_volume() only: values < 0
    origin   (x, y, z), the center of voxel (0, 0, 0), model units
    voxel    float, the voxel's edge length, model units
    band     float, model units: values at least this are clamped to it
             (inf: none)
    """

    def __init__(self, d, signed):
        self.__dict__.update(d)
        if signed:
            self.inside = self.values < 0

    def __repr__(self):
        return "<souptet.Field %s, voxel %.6g>" % ("x".join(map(str, self.values.shape)),
                                                   self.voxel)


def pseudo_volume(V, F, resolution=128, *, fill_holes=True, symmetry=True):
    """The pseudo volume of a soup: which voxels are inside (soupdist -r N | soupsign).

    V, F        as mesh()
    resolution  int, voxels along the longest side of the soup's box
                (default 128, as soupdist -r; 1..65536)
    fill_holes, symmetry  as mesh() (soupsign/soupwrap --fill-holes,
                --symmetry)
    Returns a Field: .inside bool (nx, ny, nz) indexed [i, j, k], .values the
    signed distance (negative inside; exact within 3 voxels of the surface,
    clamped to .band beyond), .origin, .voxel.
    """
    return Field(_core.pseudo_volume(V, F, resolution, fill_holes=fill_holes,
                                     symmetry=symmetry), True)


def distance(V, F, resolution=128, *, band=3.0):
    """The unsigned distance from every voxel center to the nearest triangle (soupdist).

    V, F        as mesh()
    resolution  int, voxels along the longest side of the soup's box
                (default 128, as soupdist -r; 1..65536)
    band        float, voxels: distances below band voxels are exact, the
                rest clamped to band * voxel (default 3, as soupdist; at
                least 3; math.inf: every voxel, beyond the band from the
                neighbours' nearest triangles)
    Returns a Field: .values float32 (nx, ny, nz) in model units, indexed
    [i, j, k], .origin, .voxel, .band (model units).
    """
    return Field(_core.distance(V, F, resolution, band), False)


def wrap(V, F, resolution=128, *, fill_holes=True, symmetry=True):
    """A closed, oriented, 2-manifold, self-intersection-free surface around the
    soup's pseudo volume (soupwrap --surface; needs souptet._io: OpenVDB).

    V, F        as mesh()
    resolution  int, voxels of the field along the longest side (default 128,
                as soupwrap -r)
    fill_holes, symmetry  as mesh() (soupsign/soupwrap --fill-holes,
                --symmetry)
    Returns (V2, F2): float64 (n, 3) (float-representable) and int64 (m, 3).
    """
    return _load_io().wrap(V, F, resolution, fill_holes=fill_holes, symmetry=symmetry)
