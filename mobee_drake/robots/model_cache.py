"""Prepares the icub-models URDFs for Drake, once, in a per-user cache.

Drake 1.51 does not read the binary STL meshes icub-models ships, and MoBeE does not use the
models' mesh collision geometry (its collision overlay of primitives replaces it, see
``models/icub_overlay.yaml``). So, the first time a model is used, we write a copy of its URDF
into the cache with

- every ``<collision>`` element removed (collision geometry comes from the overlay),
- every ``<gazebo>`` block removed (Drake ignores them, with warnings),
- every ``<visual>`` mesh converted from STL to OBJ (for illustration in Meshcat); with the
  ``light`` meshes (the default), each one reduced to a tenth of its triangles by quadric
  decimation (``fast-simplification``; meshes of up to 600 triangles, the hands among them, are
  kept whole) and written to 0.01 mm: the robot's 273,000 triangles in 9.6 MB of OBJ become
  about 30,000 in 0.7 MB, which a browser loads in about a second (the ``full`` meshes on
  request),
- every massless leaf link (sensor, skin and DH frames: 174 of the 213 links of iCubGazeboV2_5)
  turned into a Drake ``<frame>`` on its parent link. The frames keep their names, and the plant
  gets 39 bodies instead of 213, which makes kinematics and geometry updates several times faster.

Nothing is written into the repository. The cache lives in ``$MOBEE_DRAKE_CACHE`` or
``~/.cache/mobee-drake``; each model is written into a temporary folder and renamed into place, so
an interrupted conversion never leaves a half-written model behind.
"""

import hashlib
import os
import pathlib
import xml.etree.ElementTree as ET

import icub_models

from mobee_drake.atomic_files import WriteFolderOnce, WriteTextAtomically

_MESH_PACKAGE_PREFIX = "package://iCub/meshes/"
# Changes whenever the conversion below changes, so that old cached models are not reused.
_CONVERSION_VERSION = b"4"
# The visual meshes a prepared model names: icub-models' own, or decimated for viewers.
MESH_RESOLUTIONS = ("light", "full")
# The light meshes keep this share of each mesh's triangles, and small meshes (the hands) whole
# up to LIGHT_MESH_FLOOR triangles.
LIGHT_MESH_SHARE = 0.1
LIGHT_MESH_FLOOR = 600


def CacheDirectory() -> pathlib.Path:
    """The folder under which converted models are kept."""
    root = os.environ.get("MOBEE_DRAKE_CACHE")
    return pathlib.Path(root) if root else pathlib.Path.home() / ".cache" / "mobee-drake"


def IcubModelNames() -> list[str]:
    """The robots that the installed icub-models package provides."""
    return sorted(icub_models.get_robot_names())


def IcubModelSourceFile(model_name: str) -> pathlib.Path:
    """The original URDF of ``model_name`` inside the icub-models package."""
    if model_name not in icub_models.get_robot_names():
        raise ValueError(
            f"unknown iCub model '{model_name}'; icub-models provides: "
            + ", ".join(IcubModelNames())
        )
    return pathlib.Path(icub_models.get_model_file(model_name))


def _ConvertMesh(source: pathlib.Path, destination: pathlib.Path, resolution: str) -> None:
    # Imported lazily: only the first use of a model needs them.
    import fast_simplification
    import trimesh

    mesh = trimesh.load(source, force="mesh")
    if resolution == "full":
        WriteTextAtomically(destination, mesh.export(file_type="obj"))
        return
    points, faces = mesh.vertices, mesh.faces
    keep = max(LIGHT_MESH_SHARE * len(faces), min(len(faces), LIGHT_MESH_FLOOR))
    if keep < len(faces):
        points, faces = fast_simplification.simplify(
            points, faces, target_reduction=1.0 - keep / len(faces)
        )
    # The meshes are in millimetres (the URDF scales them): 0.01 mm is finer than a pixel.
    lines = [f"v {x:.2f} {y:.2f} {z:.2f}" for x, y, z in points]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    WriteTextAtomically(destination, "\n".join(lines) + "\n")


def ValidateMeshResolution(resolution: str) -> None:
    if resolution not in MESH_RESOLUTIONS:
        raise ValueError(
            f"meshes: '{resolution}' is not one of " + ", ".join(repr(r) for r in MESH_RESOLUTIONS)
        )


def _LeafLinksToFrames(robot: ET.Element) -> None:
    """Replaces each massless, invisible leaf link on a fixed joint by a ``<frame>`` of its
    parent."""
    links = {link.get("name"): link for link in robot.findall("link")}
    parents = {joint.find("parent").get("link") for joint in robot.findall("joint")}
    for joint in robot.findall("joint"):
        child = links[joint.find("child").get("link")]
        if (
            joint.get("type") != "fixed"
            or child.get("name") in parents
            or child.find("inertial") is not None
            or child.find("visual") is not None
        ):
            continue
        origin = joint.find("origin")
        frame = ET.SubElement(
            robot, "frame", name=child.get("name"), link=joint.find("parent").get("link")
        )
        frame.set("xyz", origin.get("xyz", "0 0 0") if origin is not None else "0 0 0")
        frame.set("rpy", origin.get("rpy", "0 0 0") if origin is not None else "0 0 0")
        robot.remove(joint)
        robot.remove(child)


def PreparedIcubModel(model_name: str, meshes: str = "light") -> pathlib.Path:
    """Returns the Drake-ready URDF of ``model_name`` with its ``meshes`` (one of
    ``MESH_RESOLUTIONS``), converting it on first use."""
    ValidateMeshResolution(meshes)
    source = IcubModelSourceFile(model_name)
    text = source.read_bytes()
    digest = hashlib.sha256(_CONVERSION_VERSION + text).hexdigest()[:12]
    folder = CacheDirectory() / "icub" / f"{model_name}-{meshes}-{digest}"
    urdf = folder / "model.urdf"
    if urdf.is_file():
        return urdf

    mesh_root = pathlib.Path(icub_models.get_models_path()).parent / "meshes"
    mesh_cache = CacheDirectory() / "icub" / f"meshes-{meshes}-{_CONVERSION_VERSION.decode()}"
    mesh_cache.mkdir(parents=True, exist_ok=True)

    tree = ET.ElementTree(ET.fromstring(text))
    robot = tree.getroot()
    for gazebo in robot.findall("gazebo"):
        robot.remove(gazebo)
    for link in robot.findall("link"):
        for collision in link.findall("collision"):
            link.remove(collision)
        for mesh in link.iter("mesh"):
            uri = mesh.get("filename", "")
            if not uri.startswith(_MESH_PACKAGE_PREFIX):
                raise ValueError(
                    f"{source}: link '{link.get('name')}' has a mesh outside the "
                    f"iCub package: {uri}"
                )
            relative = pathlib.Path(uri[len(_MESH_PACKAGE_PREFIX) :])
            converted = mesh_cache / (relative.stem + ".obj")
            if not converted.is_file():
                _ConvertMesh(mesh_root / relative, converted, meshes)
            mesh.set("filename", str(converted))

    _LeafLinksToFrames(robot)

    # A process that loses the race to a concurrent one uses the winner's copy.
    WriteFolderOnce(folder, lambda staging: tree.write(staging / "model.urdf"))
    return urdf
