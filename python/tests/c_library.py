"""The C library of the same build through ctypes, for the tests that hold Python's pixels
to C's: a scene filled by the test, rendered with settings by name."""

import ctypes

import numpy as np
import pytest


class HtHairParams(ctypes.Structure):
    _fields_ = [("sigma_a", ctypes.c_float * 3), ("eta", ctypes.c_float),
                ("beta_m", ctypes.c_float), ("beta_n", ctypes.c_float), ("alpha", ctypes.c_float)]


def f3(v):
    return (ctypes.c_float * 3)(*v)


def render(clib, fill, settings):
    """The scene `fill(lib, scene, ok)` makes through the C library at `clib`, rendered
    with `settings` (by name; `width` and `height` among them): rgb (height, width, 3)."""
    lib = ctypes.CDLL(str(clib))
    lib.ht_hair_params_default.restype = HtHairParams
    lib.ht_last_error.restype = ctypes.c_char_p
    ok = lambda status: status == 0 or pytest.fail(lib.ht_last_error().decode())
    device, scene, named = ctypes.c_void_p(), ctypes.c_void_p(), ctypes.c_void_p()
    ok(lib.ht_device_new(2, ctypes.byref(device)))
    ok(lib.ht_scene_new(device, ctypes.byref(scene)))
    fill(lib, scene, ok)
    ok(lib.ht_settings_new(ctypes.byref(named)))
    for k, v in settings.items():
        ok(lib.ht_settings_set(named, k.encode(), str(v).encode()))
    w, h = settings["width"], settings["height"]
    rgb = np.zeros(w * h * 3, np.float32)
    ok(lib.ht_render_with(scene, named, None, None, ctypes.c_void_p(rgb.ctypes.data), ctypes.c_size_t(rgb.size),
                          None, None, None, ctypes.c_size_t(w * h)))
    lib.ht_settings_free(named)
    lib.ht_scene_free(scene)
    lib.ht_device_free(device)
    return rgb.reshape(h, w, 3)
