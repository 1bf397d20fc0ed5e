"""The BSDF on numpy arrays: values as the library gives them, whatever the array's
layout or dtype, and every bad input refused with the library's message."""

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
