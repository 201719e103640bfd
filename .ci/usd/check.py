"""Checks a `pelt export ... -o FILE.usda` with Pixar's USD library (PyPI usd-core): the stage
opens with its metadata, the curves and mesh prims are valid (Pelt's texture offsets one vector
per point), their counts and extents are what Pelt printed (its `usd:` line), and USD's checker
reports no error: UsdUtils.ComplianceChecker where the library has it, else every validator of
UsdValidation (which replaced it in USD 26).
Usage: python check.py FILE.usda "usd: curves N points N ..." (the line `pelt export` printed)."""

import sys

from pxr import Usd, UsdGeom, UsdUtils


def fail(path, problem):
    print(f"{path}: {problem}", file=sys.stderr)
    sys.exit(1)


def printed(line):
    words = line.split()
    if not words or words[0] != "usd:":
        raise ValueError(f"not pelt's usd: line: {line!r}")
    values, key = {}, None
    for word in words[1:]:
        try:
            values.setdefault(key, []).append(float(word))
        except ValueError:
            key = word
    return values


def close(a, b, scale):
    return abs(a - b) <= 1e-4 * max(scale, 1e-6)


def main(path, line):
    want = printed(line)
    stage = Usd.Stage.Open(path)
    if not stage:
        fail(path, "the stage does not open")
    if UsdGeom.GetStageUpAxis(stage) != UsdGeom.Tokens.y:
        fail(path, f"upAxis {UsdGeom.GetStageUpAxis(stage)}, expected Y")
    if not stage.HasAuthoredMetadata("metersPerUnit") or UsdGeom.GetStageMetersPerUnit(stage) <= 0:
        fail(path, "metersPerUnit is not authored")
    if not stage.GetDefaultPrim():
        fail(path, "no defaultPrim")
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath("/Fur/Strands"))
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/Fur/Body"))
    if not curves or not mesh:
        fail(path, "no BasisCurves at /Fur/Strands or no Mesh at /Fur/Body")
    samples = curves.GetPointsAttr().GetTimeSamples()
    if len(samples) != int(want["time_samples"][0]):
        fail(path, f"{len(samples)} time samples, Pelt printed {want['time_samples'][0]}")
    time = Usd.TimeCode(samples[0]) if samples else Usd.TimeCode.Default()

    counts = curves.GetCurveVertexCountsAttr().Get(time)
    points = curves.GetPointsAttr().Get(time)
    if len(counts) != int(want["curves"][0]) or len(points) != int(want["points"][0]):
        fail(path, f"{len(counts)} curves of {len(points)} points, Pelt printed {want['curves']} {want['points']}")
    if sum(counts) != len(points):
        fail(path, f"curveVertexCounts add up to {sum(counts)}, there are {len(points)} points")
    curve_type = curves.GetTypeAttr().Get()
    minimum = 2 if curve_type == UsdGeom.Tokens.linear or curves.GetWrapAttr().Get() == UsdGeom.Tokens.pinned else 4
    if min(counts) < minimum:
        fail(path, f"a {curve_type} curve has {min(counts)} points")
    widths = curves.GetWidthsAttr().Get(time)
    # Linear curves have as many varying values as vertices, so USD may name the size either way.
    if curves.GetWidthsInterpolation() != UsdGeom.Tokens.vertex or curves.ComputeInterpolationForSize(
        len(widths), time
    ) not in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying):
        fail(path, f"{len(widths)} widths do not make a per-vertex primvar")
    colours = UsdGeom.PrimvarsAPI(curves.GetPrim()).GetPrimvar("displayColor")
    if colours.GetInterpolation() != UsdGeom.Tokens.uniform or len(colours.Get(time)) != len(counts):
        fail(path, "displayColor is not one colour per curve")

    # Pelt's texture offsets: one vector per point, sampled with the points.
    offsets = UsdGeom.PrimvarsAPI(curves.GetPrim()).GetPrimvar("pelt:textureOffset")
    if not offsets or offsets.GetInterpolation() != UsdGeom.Tokens.vertex:
        fail(path, "primvars:pelt:textureOffset is not a per-vertex primvar")
    offset_values = offsets.Get(time)
    if offsets.GetTypeName() != "vector3f[]" or len(offset_values) != len(points):
        fail(path, f"primvars:pelt:textureOffset has {len(offset_values)} values for {len(points)} points")
    if len(offsets.GetAttr().GetTimeSamples()) != len(samples):
        fail(path, "primvars:pelt:textureOffset is not sampled with the points")
    # A curve's root stands on its column: no offset.
    first = 0
    for count in counts:
        if any(abs(c) > 0 for c in offset_values[first]):
            fail(path, f"the texture offset at the root point {first} is not zero")
        first += count

    face_counts = mesh.GetFaceVertexCountsAttr().Get(time)
    indices = mesh.GetFaceVertexIndicesAttr().Get(time)
    mesh_points = mesh.GetPointsAttr().Get(time)
    valid, reason = UsdGeom.Mesh.ValidateTopology(indices, face_counts, len(mesh_points))
    if not valid:
        fail(path, f"mesh topology: {reason}")
    if len(mesh_points) != int(want["mesh_vertices"][0]) or len(face_counts) != int(want["mesh_triangles"][0]):
        fail(path, f"mesh of {len(mesh_points)} vertices and {len(face_counts)} faces, Pelt printed otherwise")
    normals = mesh.GetNormalsAttr().Get(time)
    if len(normals) != len(mesh_points):
        fail(path, f"{len(normals)} normals for {len(mesh_points)} vertices")
    st = UsdGeom.PrimvarsAPI(mesh.GetPrim()).GetPrimvar("st")
    if st and len(st.Get(time)) != len(indices):
        fail(path, "primvars:st is not one uv per face corner")

    for name, prim in (("curves_extent", curves), ("mesh_extent", mesh)):
        authored = prim.GetExtentAttr().Get(time)
        computed = UsdGeom.Boundable.ComputeExtentFromPlugins(prim, time)
        printed_extent = want[name]
        scale = max(abs(x) for x in printed_extent)
        flat = [c for corner in authored for c in corner]
        if not all(close(a, b, scale) for a, b in zip(flat, printed_extent)):
            fail(path, f"{name}: authored {list(authored)}, Pelt printed {printed_extent}")
        computed_flat = [c for corner in computed for c in corner]
        if not all(close(a, b, scale) for a, b in zip(flat, computed_flat)):
            fail(path, f"{name}: authored {list(authored)}, USD computes {list(computed)}")

    if hasattr(UsdUtils, "ComplianceChecker"):
        checker = UsdUtils.ComplianceChecker()
        checker.CheckCompliance(path)
        problems = [str(p) for p in list(checker.GetErrors()) + list(checker.GetFailedChecks())]
    else:
        from pxr import UsdValidation

        validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
        found = UsdValidation.ValidationContext(validators).Validate(stage)
        problems = [f"{e.GetName()}: {e.GetMessage()}" for e in found if e.GetType() == UsdValidation.ValidationErrorType.Error]
    if problems:
        fail(path, "USD's checker: " + "; ".join(problems))
    print(f"{path}: ok ({len(counts)} curves, {len(points)} points, {len(samples)} time samples)")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    main(sys.argv[1], sys.argv[2])
