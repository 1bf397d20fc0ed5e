"""The BSDFs on numpy arrays: values as the library gives them, whatever the array's
layout or dtype, the Huang model's the C library's bits, and every bad input refused with
the library's message."""

import ctypes

import numpy as np
import pytest

import hairtrace


def inputs(n: int, seed: int = 1):
    """h in [-1, 1], unit wo and wi, u in [0, 1): float32, contiguous."""
    rng = np.random.default_rng(seed)
    unit = lambda: (lambda v: v / np.linalg.norm(v, axis=1, keepdims=True))(rng.normal(size=(n, 3)))
    h = rng.uniform(-1, 1, n).astype(np.float32)
    u = rng.uniform(0, 1, (n, 3)).astype(np.float32)
    return h, unit().astype(np.float32), unit().astype(np.float32), u


def test_eval_gives_positive_values_and_pdf_alone_agrees():
    bsdf = hairtrace.HairBsdf(beta_m=0.25, alpha=-2.0)
    h, wo, wi, _ = inputs(1000)
    f, pdf = bsdf.eval(h, wo, wi)
    assert f.shape == (1000, 3) and pdf.shape == (1000,)
    assert f.dtype == np.float32 and pdf.dtype == np.float32
    assert np.isfinite(f).all() and (f >= 0).all() and (pdf > 0).all()
    assert np.array_equal(bsdf.pdf(h, wo, wi), pdf)


def test_float64_lists_and_non_contiguous_arrays_give_the_same_bits():
    bsdf = hairtrace.HairBsdf()
    h, wo, wi, _ = inputs(64)
    f, pdf = bsdf.eval(h, wo, wi)
    # float64 (exactly the float32 values), Python lists, strided views, Fortran order.
    wide = np.zeros((64, 6), dtype=np.float64)
    wide[:, ::2] = wo
    strided_wo = wide[:, ::2]
    assert not strided_wo.flags.c_contiguous
    for args in [
        (h.astype(np.float64), wo.astype(np.float64), wi.astype(np.float64)),
        (h.tolist(), wo.tolist(), wi.tolist()),
        (np.repeat(h, 2)[::2], strided_wo, np.asfortranarray(wi)),
    ]:
        f2, pdf2 = bsdf.eval(*args)
        assert np.array_equal(f2, f) and np.array_equal(pdf2, pdf)


def test_samples_are_unit_directions_with_eval_s_density():
    bsdf = hairtrace.HairBsdf(sigma_a=hairtrace.sigma_a_preset("light_brown"))
    h, wo, _, u = inputs(500)
    wi, f, pdf = bsdf.sample(h, wo, u)
    ok = pdf > 0
    assert ok.mean() > 0.99
    assert np.allclose(np.linalg.norm(wi[ok], axis=1), 1, atol=1e-4)
    f2, pdf2 = bsdf.eval(h[ok], wo[ok], wi[ok])
    assert np.allclose(pdf2, pdf[ok], rtol=1e-3) and np.allclose(f2, f[ok], rtol=1e-3, atol=1e-6)


def test_conversions_take_arrays_and_keep_their_shape():
    eu = np.array([[1.3, 0.3], [8.0, 0.0]])
    s = hairtrace.sigma_a_from_melanin(eu, 0.2)
    assert s.shape == (2, 2, 3)
    assert np.allclose(s[0, 0], hairtrace.sigma_a_from_melanin(1.3, 0.2).reshape(3))
    assert hairtrace.sigma_a_from_melanin(1.3).shape == (3,)
    c = hairtrace.sigma_a_from_color(np.full((4, 3), 0.5), beta_n=0.3)
    assert c.shape == (4, 3) and (c > 0).all()
    assert set(hairtrace.SIGMA_A_PRESETS) >= {"black", "white"}


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda b, h, wo, wi: b.eval(h, wo[:, :2], wi), ValueError, "wo: shape (8, 2): must be (n, 3)"),
        (lambda b, h, wo, wi: b.eval(h.reshape(2, 4), wo, wi), ValueError, "h: shape (2, 4): must be (n,)"),
        (lambda b, h, wo, wi: b.eval(h[:7], wo, wi), ValueError, "wo has 8 rows and h has 7: they must agree"),
        (lambda b, h, wo, wi: b.eval(np.array(["a"] * 8), wo, wi), TypeError, "h: cannot be read as float32"),
        (lambda b, h, wo, wi: b.eval(h, [[{}] * 3] * 8, wi), TypeError, "wo: cannot be read as float32"),
        (lambda b, h, wo, wi: b.eval(h + 2, wo, wi), ValueError, "element 0: h = "),
        (lambda b, h, wo, wi: b.eval(h, np.where(np.arange(8)[:, None] == 3, np.nan, wo), wi), ValueError, "element 3: wo = [NaN"),
        (lambda b, h, wo, wi: b.eval(h, wo, 2 * wi), ValueError, "must be a finite unit vector"),
        (lambda b, h, wo, wi: b.sample(h, wo, np.ones((8, 3))), ValueError, "element 0: u[0] = 1: must be in [0, 1)"),
        (lambda b, h, wo, wi: hairtrace.HairBsdf(beta_m=5.0), ValueError, "beta_m"),
        (lambda b, h, wo, wi: hairtrace.sigma_a_from_melanin([1.0, -1.0]), ValueError, "element 1: eumelanin = -1"),
        (lambda b, h, wo, wi: hairtrace.sigma_a_from_melanin([1.0, 2.0], [1.0, 2.0, 3.0]), ValueError, "must have one shape"),
        (lambda b, h, wo, wi: hairtrace.sigma_a_from_color([2.0, 0.5, 0.5]), ValueError, "color[0] = 2"),
        (lambda b, h, wo, wi: hairtrace.sigma_a_preset("green"), ValueError, "no such absorption preset"),
    ],
)
def test_bad_inputs_are_refused_with_the_library_s_message(call, error, message):
    h, wo, wi, _ = inputs(8)
    with pytest.raises(error) as e:
        call(hairtrace.HairBsdf(), h, wo, wi)
    assert message in str(e.value)


def huang_inputs(n: int, seed: int = 2):
    """h, wo, wi, u as `inputs`, and major axes across the fibre (n, 3), jitters (n, 2)."""
    h, wo, wi, u = inputs(n, seed)
    rng = np.random.default_rng(seed + 1)
    major = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(0.2, 1, n)])
    return h, wo, wi, u, major.astype(np.float32), rng.uniform(0, 1, (n, 2)).astype(np.float32)


class HtHuangParams(ctypes.Structure):
    _fields_ = [("sigma_a", ctypes.c_float * 3), ("eta", ctypes.c_float),
                ("roughness", ctypes.c_float), ("aspect", ctypes.c_float), ("alpha", ctypes.c_float)]


class HtHairFrame(ctypes.Structure):
    _fields_ = [("x", ctypes.c_float * 3), ("y", ctypes.c_float * 3), ("z", ctypes.c_float * 3),
                ("h", ctypes.c_float)]


def c_huang(clib, params, h, wo, wi, u, major, jitter, field):
    """Each element through the C library's Huang point at the local frame: f |cos| and
    pdf toward wi, and a sample's wi, f |cos| and pdf."""
    lib = ctypes.CDLL(str(clib))
    lib.ht_last_error.restype = ctypes.c_char_p
    ok = lambda status: status == 0 or pytest.fail(lib.ht_last_error().decode())
    prepared = ctypes.c_void_p()
    ok(lib.ht_huang_prepare(ctypes.byref(params), ctypes.byref(prepared)))
    point = (ctypes.c_uint8 * 4096 * 2)()  # room to align the 16-byte point
    at = ctypes.c_void_p((ctypes.addressof(point) + 15) // 16 * 16)
    f3 = lambda v: (ctypes.c_float * 3)(*v)
    out = np.zeros((len(h), 14), np.float32)
    for i in range(len(h)):
        frame = HtHairFrame(f3([1, 0, 0]), f3([0, 1, 0]), f3([0, 0, 1]), float(h[i]))
        ok(lib.ht_huang_point_init_world(prepared, ctypes.byref(frame), f3(wo[i]), f3(major[i]),
                                         (ctypes.c_float * 2)(*jitter[i]), ctypes.c_uint32(field), at))
        row = out[i].ctypes.data
        pointer = lambda k: ctypes.c_void_p(row + 4 * k)
        ok(lib.ht_huang_point_eval_world(at, f3(wi[i]), pointer(0), pointer(3)))
        ok(lib.ht_huang_point_sample_world(at, f3(u[i]), pointer(4), pointer(7), pointer(10), pointer(13)))
    lib.ht_huang_prepared_free(prepared)
    return out


@pytest.mark.parametrize("field", ["near", "far", "far_lit"])
def test_huang_eval_and_sample_give_the_c_library_s_bits(clib, field):
    params = dict(sigma_a=[0.8, 1.1, 2.0], eta=1.6, roughness=0.2, aspect=0.55, alpha=-2.5)
    bsdf = hairtrace.HuangBsdf(**params)
    h, wo, wi, u, major, jitter = huang_inputs(64)
    f, pdf = bsdf.eval(h, wo, wi, major=major, jitter=jitter, field=field)
    ws, fs, ps = bsdf.sample(h, wo, u, major=major, jitter=jitter, field=field)
    c = c_huang(clib, HtHuangParams((ctypes.c_float * 3)(*params["sigma_a"]), 1.6, 0.2, 0.55, -2.5),
                h, wo, wi, u, major, jitter, ["near", "far", "far_lit"].index(field))
    # f |cos| in float32, as the C call forms it.
    assert np.array_equal(f * np.abs(wi[:, 2:3]), c[:, 0:3]) and np.array_equal(pdf, c[:, 3])
    some = ps > 0
    assert some.mean() > 0.5  # random wo, the back of the fibre included
    assert np.array_equal(ws[some], c[some, 4:7]) and np.array_equal(ps, c[:, 13])
    assert np.array_equal(fs[some] * np.abs(ws[some, 2:3]), c[some, 7:10])


def test_huang_samples_have_eval_s_density_and_the_fields_differ():
    bsdf = hairtrace.HuangBsdf(aspect=0.6)
    h, wo, wi, u, major, jitter = huang_inputs(300)
    wi_s, f, pdf = bsdf.sample(h, wo, u, major=major, jitter=jitter, field="far")
    ok = pdf > 0
    assert ok.mean() > 0.5
    f2, pdf2 = bsdf.eval(h[ok], wo[ok], wi_s[ok], major=major[ok], jitter=jitter[ok], field="far")
    assert np.array_equal(pdf2, pdf[ok]) and np.array_equal(f2, f[ok])
    near = bsdf.eval(h, wo, wi, major=major, jitter=jitter)[1]
    assert not np.array_equal(near, bsdf.eval(h, wo, wi, major=major, jitter=jitter, field="far")[1])
    # The defaults: major +y and jitter 0.5 for every element.
    default = bsdf.eval(h, wo, wi)
    given = bsdf.eval(h, wo, wi, major=np.tile([0, 1, 0], (300, 1)), jitter=np.full((300, 2), 0.5))
    assert np.array_equal(default[0], given[0]) and np.array_equal(default[1], given[1])
    assert bsdf.aspect == np.float32(0.6) and "aspect=0.6" in repr(bsdf)


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda b, h, wo, wi, m, j: hairtrace.HuangBsdf(aspect=1.5), ValueError, "aspect = 1.5: must be in [0.05, 1]"),
        (lambda b, h, wo, wi, m, j: hairtrace.HuangBsdf(aspect=float("nan")), ValueError, "aspect = NaN"),
        (lambda b, h, wo, wi, m, j: hairtrace.HuangBsdf(roughness=0.0), ValueError, "roughness = 0"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, major=m[:, :2]), ValueError, "major: shape (8, 2): must be (n, 3)"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, major=np.tile([2.0, 0, 0], (8, 1))), ValueError, "element 0: major = [2, 0, 0]: lies along the fibre"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, major=np.zeros((8, 3))), ValueError, "element 0: major = [0, 0, 0]"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, major=np.where(np.arange(8)[:, None] == 5, np.nan, m)), ValueError, "element 5: major = [NaN, NaN, NaN]: must be finite"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, major=[["a"] * 3] * 8), TypeError, "major: cannot be read as float32"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, jitter=j[:7]), ValueError, "jitter has 7 rows and h has 8"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, jitter=j.reshape(4, 4)), ValueError, "jitter: shape (4, 4): must be (n, 2)"),
        (lambda b, h, wo, wi, m, j: b.sample(h, wo, wi * 0 + 0.5, jitter=np.ones((8, 2))), ValueError, "element 0: jitter[0] = 1: must be in [0, 1)"),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, wi, field="mid"), ValueError, 'field = "mid": must be "near", "far" or "far_lit"'),
        (lambda b, h, wo, wi, m, j: b.eval(h + 2, wo, wi), ValueError, "element 0: h = "),
        (lambda b, h, wo, wi, m, j: b.eval(h, wo, 2 * wi), ValueError, "must be a finite unit vector"),
        (lambda b, h, wo, wi, m, j: b.sample(h, wo, np.ones((8, 3))), ValueError, "element 0: u[0] = 1: must be in [0, 1)"),
    ],
)
def test_bad_huang_inputs_are_refused_with_the_library_s_message(call, error, message):
    h, wo, wi, _, major, jitter = huang_inputs(8)
    with pytest.raises(error) as e:
        call(hairtrace.HuangBsdf(), h, wo, wi, major, jitter)
    assert message in str(e.value)
