"""Blender: send each rendered frame's EXR to obscurad, and write its AO
beside it (or the frame with the AO added as a layer).

Render to OpenEXR MultiLayer with the Z (Depth) and Normal passes on, then
run this file once in Blender's Text Editor (or `blender -P
blender_post_render.py`, or from a startup script).  After every frame
Blender writes (a single frame, or each frame of an animation), the file
goes to obscurad and the answer is written next to it:

    frame_0001.exr  ->  frame_0001.ao.exr   (APPEND = False: the AO alone)
    frame_0001.exr  ->  frame_0001.exr      (APPEND = True: the frame with
                                             the AO added as layer LAYER)

Blender's EXRs carry no camera matrices, so the scene camera goes with
the request: its vertical field of view, clip range and world-to-camera
matrix.
Settings come from the environment: OBSCURA_SERVER (default
http://127.0.0.1:8420; unix:/PATH or tcp://HOST:PORT for the binary
protocol), OBSCURA_TOKEN, OBSCURA_CLIENT (the folder holding
obscura_client.py, default: this file's parent folder).
"""
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()
sys.path.insert(0, os.environ.get("OBSCURA_CLIENT", os.path.dirname(HERE)))
import obscura_client  # noqa: E402  (after sys.path)

SERVER = os.environ.get("OBSCURA_SERVER", "http://127.0.0.1:8420")
APPEND = False
LAYER = "AO"
PARAMS = {"radius": 0.5}


def camera_params(scene):
    """The scene camera as request parameters."""
    cam = scene.camera
    if cam is None or cam.type != "CAMERA":
        return {}
    data = cam.data
    r = scene.render
    w = r.resolution_x * r.pixel_aspect_x
    h = r.resolution_y * r.pixel_aspect_y
    fov = data.angle_y if data.sensor_fit == "VERTICAL" or (data.sensor_fit == "AUTO" and h > w) else None
    if fov is None:  # horizontal fit: the vertical angle from the aspect
        import math
        fov = 2.0 * math.atan(math.tan(data.angle_x / 2.0) * h / w)
    m = cam.matrix_world.inverted()
    w2c = [m[i][j] for i in range(4) for j in range(4)]  # row-major, column vectors
    return {"fov_y": fov * 57.29577951308232, "near": data.clip_start, "far": data.clip_end,
            "world_to_camera": w2c}


def on_render_write(scene, *args):
    path = bpy.path.abspath(scene.render.frame_path(frame=scene.frame_current))
    if not path.lower().endswith(".exr") or not os.path.exists(path):
        print("obscura: %s is not an EXR; set the output to OpenEXR MultiLayer" % path)
        return
    params = dict(PARAMS)
    params.update(camera_params(scene))
    params["preset"] = "blender"
    params["layer"] = LAYER
    if APPEND:
        params["append"] = 1
    out = path if APPEND else path[:-4] + ".ao.exr"
    try:
        obscura_client.ao(path, server=SERVER, out=out, **params)
        print("obscura: wrote %s" % out)
    except obscura_client.ObscuraError as e:
        print("obscura: %s: %s (%s)" % (path, e.message, e.code))


def register():
    handlers = bpy.app.handlers.render_write
    for h in list(handlers):
        if getattr(h, "__name__", "") == on_render_write.__name__:
            handlers.remove(h)
    handlers.append(on_render_write)


if __name__ == "__main__":
    register()
