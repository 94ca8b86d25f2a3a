#!/usr/bin/env python3
"""The peer's side of the boundary yardstick (bench/peer/boundary.sh): SPlisHSPlasH scenes
written from a pbflow run's scene (its box tank, box and sphere obstacles), so that both codes
hold the same water at rest beside the same solids, each with its own boundary model (the peer's
volume maps, Bender et al. 2019).
  boundary_scenes.py fill RUN_JSON OUT_DIR
      -> OUT_DIR/fill.json: the tank and a fluid block alone, a step long, so that the peer lays
         its own lattice (its first layer a particle's diameter from the walls)
  boundary_scenes.py scenes RUN_JSON OUT_DIR FILL_VTK SECONDS
      -> OUT_DIR/fluid.pda (that lattice less what lies in or within 1.5 radii of an obstacle),
         sphere.obj, scene.json (the pbflow scene at the peer's spacing, for bench/boundary.py),
         and a peer scene per variant: dfsph2.json, dfsph.json, pbf2.json, pbf2cfl.json (VARIANTS)"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from boundary import distance_to  # noqa: E402
from make_meshes import icosphere, write_obj  # noqa: E402
from peer.vtk_run import field  # noqa: E402

# The peer's particle volume is 0.8 (2r)^3 (SPlisHSPlasH's FluidModel): r at which a particle
# weighs what pbflow's does at its spacing s, whose volume is s^3.
VOLUME_FACTOR = 0.8
# The peer's lattice (spacing 2r) settles ~20 % lower: its block is this much taller, so that
# the surface stands where pbflow's does (bench/boundary.py leaves out 2 h below it).
FILL_HEIGHT = 1.25

# The peer's PBF at 2 iterations, as pbflow's pbf@2.
PBF2 = {"PBF": {"minIterations": 2, "maxIterations": 2, "maxError": 0.01, "velocityUpdateMethod": 0}}
# variant -> (simulationMethod, the solver's block, fixed step or None for the peer's CFL step).
VARIANTS = {
    "dfsph2": (4, {"DFSPH": {"maxIterations": 2, "maxError": 0.01, "maxIterationsV": 2, "maxErrorV": 0.1,
                             "enableDivergenceSolver": True}}, None),
    "dfsph": (4, {"DFSPH": {"maxIterations": 100, "maxError": 0.01, "maxIterationsV": 100, "maxErrorV": 0.1,
                            "enableDivergenceSolver": True}}, None),
    "pbf2": (2, PBF2, "pbflow"),
    "pbf2cfl": (2, PBF2, None),
}


def radius(scene):
    return scene["particle_spacing"] / (2 * VOLUME_FACTOR ** (1 / 3))


def rigid_body(mesh, translation, scale, tank=False):
    """A static peer rigid body with a volume map of 40^3 nodes; a tank's map inverted."""
    return {"geometryFile": mesh, "isDynamic": False, "isWall": tank, "mapInvert": tank,
            "translation": translation, "scale": scale, "rotationAxis": [1, 0, 0], "rotationAngle": 0,
            "mapThickness": 0.0, "mapResolution": [40, 40, 40]}


def box_body(box, unit_box, tank):
    """The peer's unit box stretched over box {min, max}."""
    return rigid_body(unit_box, [(a + b) / 2 for a, b in zip(box["min"], box["max"])],
                      [b - a for a, b in zip(box["min"], box["max"])], tank)


def rigid_bodies(scene, unit_box, sphere):
    out = [box_body(scene["domain"], unit_box, True)]
    for o in scene.get("obstacles", []):
        if o.get("type") == "sphere":
            out.append(rigid_body(sphere, o["centre"], [o["radius"]] * 3))
        elif o.get("type", "box") == "box":
            out.append(box_body(o, unit_box, False))
        else:
            raise SystemExit(f"boundary_scenes.py: an obstacle of type {o.get('type')} has no peer here")
    return out


def configuration(scene, seconds, method, solver, step):
    c = {"stopAt": seconds, "particleRadius": radius(scene), "simulationMethod": method,
         "gravitation": scene.get("gravity", [0, -9.81, 0]), "boundaryHandlingMethod": 2,
         "enableVTKExport": True, "particleAttributes": "density;velocity", "dataExportFPS": 10,
         "enablePartioExport": False}
    if step == "pbflow":  # pbflow's real-time step: its fps and 2 substeps
        c.update(cflMethod=0, timeStepSize=1.0 / (scene.get("fps", 60) * 2))
    else:
        c.update(cflMethod=1, timeStepSize=0.001, cflMaxTimeStepSize=0.005)
    c.update(solver)
    return c


def peer_scene(config, rigid, fluid):
    return {"Configuration": config, "RigidBodies": rigid, "FluidModels": fluid,
            "Materials": [{"id": "Fluid", "density0": 1000, "viscosityMethod": 1,
                           "Standard viscosity": {"viscosity": 0.01}}]}


def fill(scene, out, unit_box):
    block = scene["fluid_blocks"][0]
    top = block["min"][1] + FILL_HEIGHT * (block["max"][1] - block["min"][1])
    tank = [box_body(scene["domain"], unit_box, True)]
    s = peer_scene(configuration(scene, 0.01, 4, VARIANTS["dfsph2"][1], None), tank, [])
    del s["FluidModels"]
    s["FluidBlocks"] = [{"denseMode": 0, "start": block["min"], "end": [block["max"][0], top, block["max"][2]]}]
    json.dump(s, open(os.path.join(out, "fill.json"), "w"), indent=1)


def inside(o, p):
    if o.get("type") == "sphere":
        return math.dist(p, o["centre"]) < o["radius"]
    return all(o["min"][a] < p[a] < o["max"][a] for a in range(3))


def scenes(scene, out, unit_box, fill_vtk, seconds):
    r = radius(scene)
    points = field(open(fill_vtk, "rb").read(), rb"POINTS", 3)
    obstacles = scene.get("obstacles", [])
    kept = [p for p in points if not any(inside(o, p) or distance_to(o, p) < 1.5 * r for o in obstacles)]
    with open(os.path.join(out, "fluid.pda"), "w") as f:
        f.write("ATTRIBUTES\nposition\nTYPES\nV\nNUMBER_OF_PARTICLES: %d\nBEGIN DATA\n" % len(kept))
        f.writelines("%.6f %.6f %.6f\n" % tuple(p) for p in kept)
    v, faces = icosphere(5)  # a unit sphere, edges ~0.06 of its radius
    sphere = os.path.join(out, "sphere.obj")
    write_obj(sphere, v, faces)
    rigid = rigid_bodies(scene, unit_box, sphere)
    fluid = [{"particleFile": os.path.join(out, "fluid.pda"), "translation": [0, 0, 0], "scale": [1, 1, 1]}]
    for name, (method, solver, step) in VARIANTS.items():
        s = peer_scene(configuration(scene, seconds, method, solver, step), rigid, fluid)
        json.dump(s, open(os.path.join(out, name + ".json"), "w"), indent=1)
    json.dump(dict(scene, particle_spacing=2 * r), open(os.path.join(out, "scene.json"), "w"), indent=1)
    print(f"{len(kept)} peer particles, radius {r:.6f} m")


def main(args):
    if len(args) < 3 or args[0] not in ("fill", "scenes") or (args[0] == "scenes" and len(args) < 5):
        raise SystemExit(__doc__)
    scene, out = json.load(open(args[1]))["scene"], os.path.abspath(args[2])
    os.makedirs(out, exist_ok=True)
    sim_root = os.environ.get("PEER_ROOT")
    if not sim_root:
        raise SystemExit("boundary_scenes.py: PEER_ROOT (the peer's checkout) is not set")
    unit_box = os.path.join(sim_root, "data", "models", "UnitBox.obj")
    if args[0] == "fill":
        fill(scene, out, unit_box)
    else:
        scenes(scene, out, unit_box, args[3], float(args[4]))


if __name__ == "__main__":
    main(sys.argv[1:])
