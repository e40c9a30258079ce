#!/usr/bin/env python3
"""Converts ICT-FaceKit's FaceXModel/ (USC ICT, MIT licence, github.com/ICT-VGL/ICT-FaceKit) into
ICEF's one-file face model, models/ict-facekit/ict_facekit.bin (format: models/ict-facekit/README.md;
loader: src/icef/face/ict_model.h).

    git clone https://github.com/ICT-VGL/ICT-FaceKit.git
    /usr/bin/python3 scripts/convert_ict_facekit.py ICT-FaceKit --out models/ict-facekit/

SOURCE is a checkout of the repository (a directory holding FaceXModel/), or a bare git directory,
read with `git show REV:FaceXModel/...` (--rev, default HEAD). Needs numpy only (Debian's
/usr/bin/python3 has it). The facts this script does not read from the OBJs (part vertex ranges,
the jawline index lists) are transcribed from ICT-FaceKit's README.md and checked against the mesh.
"""
import argparse
import hashlib
import json
import os
import struct
import subprocess
import sys

import numpy as np

MAGIC = b"ICTFK1\0\0"
HEADER_FORMAT = "<8s10I40sQ"  # magic, 10 counts/codes, source commit (40 ASCII hex), file size
DTYPE_F16, DTYPE_F32 = 1, 2
NUM_IDENTITIES = 100
# The 53 expressions: ARKit's 52 blendshapes less tongueOut, with browInnerUp and cheekPuff split
# into _L/_R; ICT spells ARKit's Left/Right as _L/_R (mouthSmileLeft -> mouthSmile_L).
EXPRESSIONS = [
    "browDown_L", "browDown_R", "browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R",
    "cheekPuff_L", "cheekPuff_R", "cheekSquint_L", "cheekSquint_R", "eyeBlink_L", "eyeBlink_R",
    "eyeLookDown_L", "eyeLookDown_R", "eyeLookIn_L", "eyeLookIn_R", "eyeLookOut_L", "eyeLookOut_R",
    "eyeLookUp_L", "eyeLookUp_R", "eyeSquint_L", "eyeSquint_R", "eyeWide_L", "eyeWide_R",
    "jawForward", "jawLeft", "jawOpen", "jawRight", "mouthClose", "mouthDimple_L", "mouthDimple_R",
    "mouthFrown_L", "mouthFrown_R", "mouthFunnel", "mouthLeft", "mouthLowerDown_L", "mouthLowerDown_R",
    "mouthPress_L", "mouthPress_R", "mouthPucker", "mouthRight", "mouthRollLower", "mouthRollUpper",
    "mouthShrugLower", "mouthShrugUpper", "mouthSmile_L", "mouthSmile_R", "mouthStretch_L",
    "mouthStretch_R", "mouthUpperUp_L", "mouthUpperUp_R", "noseSneer_L", "noseSneer_R"]
# Per-vertex parts: ICT-FaceKit README "Face Model Topology" (inclusive vertex index ranges), with
# each eyeball split into sclera and iris as in its "Eyeball Details" table.
PARTS = [
    ("face", 0, 9408), ("head_neck", 9409, 11247), ("mouth_socket", 11248, 13293),
    ("eye_socket_left", 13294, 13677), ("eye_socket_right", 13678, 14061),
    ("gums_tongue", 14062, 17038), ("teeth", 17039, 21450),
    ("sclera_left", 21451, 22220), ("iris_left", 22221, 23020),
    ("sclera_right", 23021, 23790), ("iris_right", 23791, 24590),
    ("lacrimal_fluid_left", 24591, 24794), ("lacrimal_fluid_right", 24795, 24998),
    ("eye_blend_left", 24999, 25022), ("eye_blend_right", 25023, 25046),
    ("eye_occlusion_left", 25047, 25198), ("eye_occlusion_right", 25199, 25350),
    ("eyelashes_left", 25351, 26034), ("eyelashes_right", 26035, 26718)]
# Index lists given only in ICT-FaceKit's README "Facial Landmarks" (vertex indices).
README_SETS = {
    "jawline_right": [1278, 1272, 12, 1834, 243, 781, 2199, 1447],
    "jawline_left": [3661, 4390, 3022, 2484, 4036, 2253, 3490, 3496],
    "jawline_right_extended": [1280, 1278, 1275, 1272, 1248, 12, 820, 1834, 1902, 243, 844, 781, 1673,
                               2199, 801, 1447, 800],
    "jawline_left_extended": [3041, 3661, 3042, 4390, 3880, 3022, 3085, 2484, 4102, 4036, 3061, 2253,
                              3466, 3490, 3493, 3496, 3498],
    "narrow_face_area": list(range(0, 6706)),  # README "Face Area Details": vertices [0:6705]
}
# Vertex index lists of FaceXModel/vertex_indices.json stored as vertex sets (name without "idx_to_").
JSON_SETS = ["idx_to_fitting_verts", "idx_to_rigid_verts", "idx_to_lap_rigid_verts"]


class Source:
    """Reads FaceXModel/ files from a checkout or a bare git directory."""

    def __init__(self, path, rev):
        self.path = path
        self.bare = not os.path.isdir(os.path.join(path, "FaceXModel"))
        if self.bare:
            self.commit = self._git("rev-parse", f"{rev}^{{commit}}").decode().strip()
        else:
            try:
                self.commit = self._git("rev-parse", "HEAD").decode().strip()
            except SystemExit:
                self.commit = "0" * 40  # a plain copy without git metadata
        if len(self.commit) != 40:
            sys.exit(f"{path}: cannot resolve the source commit")

    def _git(self, *args):
        cmd = ["git", "--git-dir", self.path] if self.bare else ["git", "-C", self.path]
        r = subprocess.run(cmd + list(args), capture_output=True)
        if r.returncode != 0:
            sys.exit(f"{self.path}: git {' '.join(args)} failed: {r.stderr.decode().strip()}")
        return r.stdout

    def read(self, name, folder="FaceXModel/"):
        if self.bare:
            return self._git("show", f"{self.commit}:{folder}{name}").decode()
        with open(os.path.join(self.path, folder, name)) as f:
            return f.read()


def parse_obj(text, name, full):
    """Returns (vertices [V,3] float64, uvs [U,2], polygons [(vi, ti)], topology digest)."""
    verts, uvs, polys, topo = [], [], [], hashlib.sha256()
    for line in text.splitlines():
        if line.startswith("v "):
            verts.append(line.split()[1:4])
        elif not full:
            if line.startswith("f ") or line.startswith("vt "):
                topo.update(line.encode())
        elif line.startswith("vt "):
            uvs.append(line.split()[1:3])
            topo.update(line.encode())
        elif line.startswith("f "):
            topo.update(line.encode())
            corners = [c.split("/") for c in line.split()[1:]]
            if any(len(c) < 2 or not c[1] for c in corners):
                sys.exit(f"{name}: face without texture coordinates: {line}")
            polys.append(([int(c[0]) - 1 for c in corners], [int(c[1]) - 1 for c in corners]))
    v = np.array(verts, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        sys.exit(f"{name}: no vertices")
    return v, np.array(uvs, dtype=np.float64), polys, topo.hexdigest()


def triangulate(polys):
    """Fan-splits each polygon (a, b, c, d) -> (a, b, c), (a, c, d), keeping the OBJ's winding."""
    tris, tri_uvs = [], []
    for vi, ti in polys:
        if len(vi) not in (3, 4):
            sys.exit(f"polygon with {len(vi)} corners (expected triangles and quads)")
        for k in range(1, len(vi) - 1):
            tris.append((vi[0], vi[k], vi[k + 1]))
            tri_uvs.append((ti[0], ti[k], ti[k + 1]))
    return np.array(tris, dtype=np.uint32), np.array(tri_uvs, dtype=np.uint32)


def measure_f16(name, deltas, head_height):
    """Prints and returns the max |float16 - exact| over the deltas [K, V, 3] (model units)."""
    err = np.abs(deltas.astype(np.float16).astype(np.float64) - deltas).max()
    print(f"  {name}: max |delta| {np.abs(deltas).max():.4f} cm, float16 max error {err:.3e} cm "
          f"= {err / head_height:.2e} of the head height")
    return err


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("source", help="ICT-FaceKit checkout or bare git directory")
    ap.add_argument("--out", required=True, help="output directory (models/ict-facekit/)")
    ap.add_argument("--rev", default="HEAD", help="revision to read from a bare git directory")
    ap.add_argument("--max-rel-error", type=float, default=1e-4,
                    help="largest float16 error, relative to the head height, stored as float16")
    args = ap.parse_args()
    src = Source(args.source, args.rev)
    print(f"source {args.source} commit {src.commit}")

    neutral_name = "generic_neutral_mesh.obj"
    neutral, uvs, polys, neutral_topo = parse_obj(src.read(neutral_name), neutral_name, True)
    V = len(neutral)
    n_quads = sum(len(p[0]) == 4 for p in polys)
    tris, tri_uvs = triangulate(polys)
    print(f"neutral: {V} vertices, {len(uvs)} uvs, {len(polys)} polygons ({n_quads} quads, "
          f"{len(polys) - n_quads} triangles) -> {len(tris)} triangles")
    if tris.max() >= V or tri_uvs.max() >= len(uvs):
        sys.exit("generic_neutral_mesh.obj: face index out of range")

    config = json.loads(src.read("vertex_indices.json"))
    if config["expressions"] != EXPRESSIONS:
        sys.exit("vertex_indices.json: the expression list differs from the 53 this script expects")

    def read_target(name):
        v, _, _, t = parse_obj(src.read(name + ".obj"), name + ".obj", False)
        if v.shape != neutral.shape:
            sys.exit(f"{name}.obj: {len(v)} vertices, the neutral has {V}")
        return v - neutral, t

    # The topology of every target must equal the neutral's (digest over the vt and f lines).
    identities, expressions = [], []
    for i in range(NUM_IDENTITIES):
        d, t = read_target(f"identity{i:03d}")
        if t != neutral_topo:
            sys.exit(f"identity{i:03d}.obj: topology differs from the neutral")
        identities.append(d)
    for name in EXPRESSIONS:
        d, t = read_target(name)
        if t != neutral_topo:
            sys.exit(f"{name}.obj: topology differs from the neutral")
        expressions.append(d)
    identities, expressions = np.array(identities), np.array(expressions)
    norms = np.linalg.norm(identities.reshape(NUM_IDENTITIES, -1), axis=1)
    print(f"identity modes: L2 norm {norms[0]:.1f} (mode 0) .. {norms[-1]:.2f} (mode 99): "
          "scaled by their standard deviations (ICT's sampler draws N(0, 1) coefficients)")

    # Parts: the README's ranges must tile [0, V) and no polygon may join two parts other than
    # face/head_neck (one surface).
    labels = np.full(V, 255, dtype=np.uint8)
    for k, (name, a, b) in enumerate(PARTS):
        if not (labels[a:b + 1] == 255).all():
            sys.exit(f"part {name}: range overlaps another")
        labels[a:b + 1] = k
    if (labels == 255).any():
        sys.exit("the part ranges do not cover every vertex")
    tri_parts = labels[tris]
    mixed = tri_parts.min(1) != tri_parts.max(1)
    joined = {tuple(sorted({PARTS[p][0] for p in row})) for row in tri_parts[mixed]}
    print(f"parts: {len(PARTS)}; triangles joining two parts: {int(mixed.sum())} {sorted(joined)}")

    # Orientation and size.
    lo, hi = neutral.min(0), neutral.max(0)
    head_height = hi[1] - lo[1]
    print(f"neutral bbox min {lo.round(3)} max {hi.round(3)} (cm; +y up, the face looks down +z): "
          f"head height {head_height:.2f}")
    landmarks = np.array(config["idx_to_landmark_verts"], dtype=np.int32)
    if len(landmarks) != 68 or landmarks.min() < 0 or landmarks.max() >= V:
        sys.exit("vertex_indices.json: idx_to_landmark_verts is not 68 vertex indices")
    print(f"landmarks: 68 iBUG/Multi-PIE vertex indices; iBUG 0 (subject's right jaw) at x = "
          f"{neutral[landmarks[0], 0]:.2f}, iBUG 16 at x = {neutral[landmarks[16], 0]:.2f}")
    f = neutral[tris[:, 0]], neutral[tris[:, 1]], neutral[tris[:, 2]]
    normals = np.cross(f[1] - f[0], f[2] - f[0])
    nose = int(landmarks[30])
    around = np.nonzero((tris == nose).any(1))[0]
    print(f"winding: normals at the nose tip have mean z {normals[around, 2].mean():+.4f} "
          "(> 0: counter-clockwise seen from outside)")

    # Precision: float16 where its error is below --max-rel-error of the head height.
    print("float16 storage of the deltas:")
    dtypes = []
    for name, d in (("identity modes", identities), ("expression deltas", expressions)):
        err = measure_f16(name, d, head_height)
        dtypes.append(DTYPE_F16 if err <= args.max_rel_error * head_height else DTYPE_F32)
    rng = np.random.default_rng(0)
    c_id = rng.standard_normal((8, NUM_IDENTITIES))
    c_ex = rng.uniform(0, 1, (8, len(EXPRESSIONS)))
    id16 = identities.astype(np.float16).astype(np.float64)
    ex16 = expressions.astype(np.float16).astype(np.float64)
    mesh_err = max(np.abs(np.tensordot(a, id16 - identities, 1)
                          + np.tensordot(b, ex16 - expressions, 1)).max() for a, b in zip(c_id, c_ex))
    print(f"  mesh at 8 random (identity ~ N(0,1), expression ~ U(0,1)): max vertex error "
          f"{mesh_err:.3e} cm = {mesh_err / head_height:.2e} of the head height")

    sets = {name[len("idx_to_"):]: config[name] for name in JSON_SETS}
    sets.update(README_SETS)
    for name, idx in sets.items():
        if min(idx) < 0 or max(idx) >= V:
            sys.exit(f"vertex set {name}: index out of range")

    blocks = [
        neutral.astype("<f4").tobytes(), tris.astype("<u4").tobytes(), uvs.astype("<f4").tobytes(),
        tri_uvs.astype("<u4").tobytes(),
        identities.astype("<f2" if dtypes[0] == DTYPE_F16 else "<f4").tobytes(),
        expressions.astype("<f2" if dtypes[1] == DTYPE_F16 else "<f4").tobytes()]

    def strings(names):
        out = b""
        for s in names:
            e = s.encode("ascii")
            if not 0 < len(e) < 256:
                sys.exit(f"name {s!r}: length out of range")
            out += struct.pack("<B", len(e)) + e
        return out

    blocks += [strings(EXPRESSIONS), strings(p[0] for p in PARTS), labels.tobytes(),
               landmarks.astype("<i4").tobytes()]
    for name, idx in sets.items():
        blocks.append(strings([name]) + struct.pack("<I", len(idx)) + np.array(idx, dtype="<u4").tobytes())
    body = b"".join(blocks)
    size = struct.calcsize(HEADER_FORMAT) + len(body)
    header = struct.pack(HEADER_FORMAT, MAGIC, V, len(tris), len(uvs), NUM_IDENTITIES, len(EXPRESSIONS),
                         len(PARTS), len(landmarks), len(sets), dtypes[0], dtypes[1],
                         src.commit.encode("ascii"), size)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "ict_facekit.bin")
    with open(path + ".tmp", "wb") as out:
        out.write(header + body)
    os.replace(path + ".tmp", path)
    with open(os.path.join(args.out, "LICENSE"), "w") as out:
        out.write(src.read("LICENSE", folder=""))
    print(f"wrote {path}: {size} bytes ({size / 1e6:.2f} MB); identity modes "
          f"{'float16' if dtypes[0] == DTYPE_F16 else 'float32'}, expression deltas "
          f"{'float16' if dtypes[1] == DTYPE_F16 else 'float32'}; vertex sets "
          + ", ".join(f"{k} ({len(v)})" for k, v in sets.items()))
    if size > 30_000_000:
        sys.exit(f"{path}: {size} bytes is over the 30 MB budget")


if __name__ == "__main__":
    main()
