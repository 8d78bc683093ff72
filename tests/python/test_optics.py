"""thzmap.atmosphere, material_library, surface_optics, planck_radiance and
brightness_temperature: the air's attenuation equal to what `thzmap atmosphere` prints,
the library's names as `thzmap materials` lists them and its optics obeying the complex
index's identities, a scene's surfaces agreeing with the library entries they name and
with Kirchhoff (eps = 1 - R - T), Planck's law against its closed form, and errors."""
import csv
import io
import math
import os

import numpy as np
import pytest
from conftest import REPO

import thzmap

H, C, K_B = 6.62607015e-34, 299792458.0, 1.380649e-23  # SI, exact


def cli_atmosphere(binary, *args):
    import subprocess
    p = subprocess.run([binary, "atmosphere", "--from-thz", "0.2", "--to-thz", "1.0",
                        "--step-ghz", "50", *args], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rows = [r for r in p.stdout.splitlines() if not r.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(rows))))


@pytest.mark.parametrize("model,columns", [
    ("lines", ["h2o_lines", "h2o_continuum", "o2", "dry_continuum"]),
    ("itu-p676", ["h2o", "o2", "dry_continuum"])])
def test_attenuation_equals_the_command(thzmap_binary, model, columns):
    rows = cli_atmosphere(thzmap_binary, "--model", model, "--relative-humidity", "0.6",
                          "--temperature-k", "296", "--distance-m", "25")
    f = np.array([float(r["frequency_thz"]) for r in rows])
    air = thzmap.atmosphere(model, temperature_k=296, relative_humidity=0.6)
    assert air.info.temperature_k == 296 and air.info.has_air == 1
    parts = air.attenuation(f)
    # the CSV holds 7 significant digits
    np.testing.assert_allclose(parts["total_per_m"],
                               [float(r["attenuation_per_m"]) for r in rows], rtol=1e-6)
    np.testing.assert_allclose(air.attenuation_db_per_km(f),
                               [float(r["attenuation_db_per_km"]) for r in rows], rtol=1e-6)
    np.testing.assert_allclose(air.transmittance(f, 25),
                               [float(r["transmittance"]) for r in rows], rtol=1e-6)
    names = {"h2o_lines": "h2o_lines_per_m", "h2o": "h2o_lines_per_m",
             "h2o_continuum": "h2o_continuum_per_m", "o2": "o2_per_m",
             "dry_continuum": "dry_continuum_per_m"}
    for c in columns:
        np.testing.assert_allclose(parts[names[c]] * 1e4 / math.log(10),
                                   [float(r[f"{c}_db_per_km"]) for r in rows], rtol=1e-6,
                                   err_msg=c)
    # shapes: a number gives a float, a 2-D array an array of its shape
    assert isinstance(air.attenuation_per_m(0.35), float)
    assert air.attenuation_per_m(np.full((2, 3), 0.35)).shape == (2, 3)



@pytest.mark.parametrize("args,kwargs", [
    (["--water-vapour-g-m3", "12"], {"water_vapour_g_m3": 12}),
    (["--h2o-vmr", "0.004"], {"h2o_vmr": 0.004}),
    (["--no-continuum", "--pressure-hpa", "900"], {"continuum": False, "pressure_hpa": 900})])
def test_each_humidity_and_the_continuum_as_the_command(thzmap_binary, args, kwargs):
    """Each way to give the humidity, and continuum=False, mean what the command's
    options mean: the same attenuation."""
    rows = cli_atmosphere(thzmap_binary, *args)
    f = np.array([float(r["frequency_thz"]) for r in rows])
    np.testing.assert_allclose(thzmap.atmosphere(**kwargs).attenuation_per_m(f),
                               [float(r["attenuation_per_m"]) for r in rows], rtol=1e-6)

def test_the_scene_atmosphere_and_dry_air():
    scene = thzmap.load_scene(os.path.join(REPO, "examples", "outdoor-concealed", "scene.json"))
    a = thzmap.atmosphere(scene=scene)
    assert a.model == "itu-p676" and a.info.emitting == 1
    assert a.info.background_temperature_k == 40
    same = thzmap.atmosphere("itu-p676", temperature_k=288, pressure_hpa=1013,
                             relative_humidity=0.5)
    f = np.linspace(0.1, 1.0, 10)
    np.testing.assert_array_equal(a.attenuation_per_m(f), same.attenuation_per_m(f))
    dry = thzmap.atmosphere("lines", h2o_vmr=0)
    parts = dry.attenuation(f)
    assert not parts["h2o_lines_per_m"].any() and parts["o2_per_m"].all()
    assert thzmap.atmosphere("none").attenuation_per_m(0.5) == 0.0
    # no air to describe: refused, as `thzmap atmosphere --model none --humidity ...` is
    with pytest.raises(thzmap.ArgumentError, match="relative_humidity: .*no air"):
        thzmap.atmosphere("none", relative_humidity=0.5)
    with pytest.raises(thzmap.ArgumentError, match="temperature_k, pressure_hpa: "):
        thzmap.atmosphere("none", temperature_k=290, pressure_hpa=1000)


def test_material_library(thzmap_binary):
    import subprocess
    lib = thzmap.material_library()
    listing = subprocess.run([thzmap_binary, "materials"], capture_output=True,
                             text=True).stdout
    listed = [line.split()[0] for line in listing.splitlines()[3:]
              if line and not line.startswith(" ")]
    assert lib.names == listed and len(lib) == len(listed) >= 30
    water = lib.info("water")
    assert water.model == "double-debye" and "Liebe" in water.source
    assert water.has_valid_range and water.valid_to_thz == 1.0
    # `thzmap materials water` tabulates f, n, k, eps', eps'', alpha and R(0) to 5 digits
    table = [line.split() for line in subprocess.run(
        [thzmap_binary, "materials", "water"], capture_output=True, text=True).stdout.splitlines()
        if line.strip() and line.split()[0].replace(".", "").isdigit() and "*" not in line]
    f = np.array([float(r[0]) for r in table])
    assert len(f) >= 4 and f.max() == 1.0
    o = lib.optics("water", f)
    for j, got in enumerate([o.n, o.k, o.eps_real, o.eps_imag, o.attenuation_per_m,
                             o.normal_reflectance]):
        np.testing.assert_allclose(got, [float(r[j + 1]) for r in table], rtol=6e-5)
    m = o.n + 1j * o.k
    # the identities of a complex index
    np.testing.assert_allclose(o.eps_real + 1j * o.eps_imag, m * m, rtol=1e-12)
    np.testing.assert_allclose(o.normal_reflectance, np.abs((m - 1) / (m + 1)) ** 2, rtol=1e-12)
    np.testing.assert_allclose(o.attenuation_per_m, 4 * math.pi * o.k * f * 1e12 / C,
                               rtol=1e-12)
    with pytest.raises(thzmap.ArgumentError, match="outside the range"):
        lib.optics("water", 2.0)  # stated for 1-1000 GHz, as a scene is refused
    with pytest.raises(thzmap.ArgumentError, match="unobtainium"):
        lib.optics("unobtainium", 1.0)


C = 299792458.0  # m/s


def slab_means(n, k, f_thz, t_m, intervals=20000):
    """T-bar and R-bar = 2 int_0^1 X(mu) mu dmu of a slab of n + ik, t_m thick, in air
    (docs/physics.md "Fresnel reflectance and slabs"), each frequency by Simpson's rule."""
    n, k, f_thz = (np.asarray(a, dtype=float)[:, None] for a in (n, k, f_thz))
    mu = np.linspace(0.0, 1.0, intervals + 1)[None, :]
    s2 = 1 - mu**2
    index = n + 1j * k
    q = np.sqrt(index**2 - s2 + 0j)
    q = np.where(q.imag < 0, -q, q)
    tau = np.exp(-4 * np.pi * k * f_thz * 1e12 / C * t_m / (q.real / np.sqrt(s2 + q.real**2)))
    t = r = 0
    for face in ((mu - q) / (mu + q), (index**2 * mu - q) / (index**2 * mu + q)):
        rf = np.abs(face)**2
        t = t + 0.5 * (1 - rf)**2 * tau / (1 - rf**2 * tau**2)
        r = r + 0.5 * (rf + (1 - rf)**2 * rf * tau**2 / (1 - rf**2 * tau**2))
    weights = np.ones(intervals + 1)
    weights[1:-1:2], weights[2:-1:2] = 4, 2
    h = 1.0 / intervals
    return (2 * h / 3 * (weights * t * mu).sum(axis=1),
            2 * h / 3 * (weights * r * mu).sum(axis=1))


def test_surface_optics_agree_with_the_library_and_kirchhoff():
    scene = thzmap.load_scene(os.path.join(REPO, "examples", "outdoor-concealed", "scene.json"))
    lib = thzmap.material_library()
    f = np.array([0.2, 0.35, 0.6])
    skin = thzmap.surface_optics(scene, "skin", f)
    ref = lib.optics("skin", f)
    assert skin.has_index == 1
    np.testing.assert_allclose(skin.reflectance_normal, ref.normal_reflectance, rtol=1e-12)
    np.testing.assert_allclose(skin.n, ref.n, rtol=1e-12)
    # an opaque half-space: eps = 1 - R, nothing through; a slab: eps = 1 - R - T
    np.testing.assert_allclose(skin.emissivity_normal, 1 - skin.reflectance_normal, rtol=1e-12)
    np.testing.assert_allclose(skin.emissivity_mean, 1 - skin.reflectance_mean, rtol=1e-12)
    assert not skin.transmission_mean.any()
    denim = thzmap.surface_optics(scene, "denim", f, thickness_m=0.0005)
    # a slab's T-bar and R-bar from docs/physics.md's formulas, by Simpson's rule over mu
    # (the library sums 48 Gauss-Legendre points): the bindings' fields in their places
    # and the slab's multiple reflections, not just 0.05 < T-bar < 1
    t_mean, r_mean = slab_means(denim.n, denim.k, f, 0.0005)
    np.testing.assert_allclose(denim.transmission_mean, t_mean, rtol=1e-9)
    np.testing.assert_allclose(denim.reflectance_mean, r_mean, rtol=1e-9)
    np.testing.assert_allclose(denim.attenuation_per_m, 4 * np.pi * denim.k * f * 1e12 / C,
                               rtol=1e-12)
    np.testing.assert_allclose(denim.emissivity_mean,
                               1 - denim.reflectance_mean - denim.transmission_mean, atol=1e-12)
    thicker = thzmap.surface_optics(scene, "denim", f, thickness_m=0.005)
    assert (thicker.transmission_mean < denim.transmission_mean).all()
    with pytest.raises(thzmap.ArgumentError, match="no material"):
        thzmap.surface_optics(scene, "wool", 0.5)
    # a path wherever a Scene is taken
    path = os.path.join(REPO, "examples", "outdoor-concealed", "scene.json")
    by_path = thzmap.surface_optics(path, "denim", f, thickness_m=0.0005)
    np.testing.assert_array_equal(by_path.transmission_mean, denim.transmission_mean)
    assert thzmap.atmosphere(scene=path).info == thzmap.atmosphere(scene=scene).info


def test_planck():
    f, t = np.array([0.1, 0.5, 1.0, 3.0]), 300.0
    nu = f * 1e12
    closed = 2 * H * nu ** 3 / C ** 2 / np.expm1(H * nu / (K_B * t))
    b = thzmap.planck_radiance(f, t)
    np.testing.assert_allclose(b, closed, rtol=1e-12)
    np.testing.assert_allclose(thzmap.brightness_temperature(f, b), t, rtol=1e-12)
    # broadcasting, and 0 K for no radiance
    assert thzmap.planck_radiance(1.0, [[200.0], [300.0]]).shape == (2, 1)
    assert thzmap.brightness_temperature(1.0, 0.0) == 0.0
    # what is not a temperature or a radiance is an ArgumentError, not 0 or numpy's error
    for bad in ("x", float("nan"), -5.0, None, [1.0, 2.0]):
        with pytest.raises(thzmap.ArgumentError, match="temperature_k"):
            thzmap.planck_radiance(np.linspace(0.2, 1.0, 5), bad)
    with pytest.raises(thzmap.ArgumentError, match="radiance"):
        thzmap.brightness_temperature(0.5, float("inf"))


def test_errors():
    with pytest.raises(thzmap.ArgumentError, match="model"):
        thzmap.atmosphere("hitran")
    with pytest.raises(thzmap.ArgumentError, match="at most one"):
        thzmap.atmosphere(relative_humidity=0.5, h2o_vmr=0.01)
    with pytest.raises(thzmap.ArgumentError, match="temperature"):
        thzmap.atmosphere(temperature_k=20)
    with pytest.raises(thzmap.ArgumentError, match="above 0 THz"):
        thzmap.atmosphere().attenuation_per_m([0.5, -1.0])
    with pytest.raises(thzmap.ArgumentError, match="above 0 THz"):
        thzmap.atmosphere().attenuation_per_m(0)  # 0 Hz is no frequency either
    # a frequency in Hz (3e11 for 0.3 THz) gave B = 0 and a material's end values in silence
    scene = os.path.join(REPO, "examples", "teraeye", "scene.json")
    for call in (lambda f: thzmap.planck_radiance(f, 300.0),
                 lambda f: thzmap.brightness_temperature(f, 1e-14),
                 lambda f: thzmap.surface_optics(scene, 0, f),
                 lambda f: thzmap.atmosphere().attenuation_per_m(f)):
        with pytest.raises(thzmap.ArgumentError, match=r"3e\+11 THz is above 10000 THz"):
            call([0.3, 3e11])
        call(0.3)
    scene = os.path.join(REPO, "examples", "outdoor-concealed", "scene.json")
    for other in ({"temperature_k": 300}, {"continuum": False}, {"model": "none"}):
        with pytest.raises(thzmap.ArgumentError, match="takes no other arguments"):
            thzmap.atmosphere(scene=scene, **other)  # not silently the scene's air
    with pytest.raises(thzmap.ArgumentError, match=r"distance_m: expected a number at least 0, "
                       r"got -1"):
        thzmap.atmosphere().transmittance(0.5, -1)
    # distances as an array broadcast against the frequencies, as planck_radiance's
    # temperatures do (a sweep over path length was refused: 'expected a finite number')
    air = thzmap.atmosphere()
    f, d = np.array([0.3, 0.5, 0.65]), np.array([[1.0], [10.0]])
    t = air.transmittance(f, d)
    assert t.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            assert t[i, j] == air.transmittance(f[j], d[i, 0])
    assert np.all(t[1] < t[0])
    for bad in ([[1.0, -1.0]], [np.nan, 1.0], ["1", "2"], [1.0, 2.0]):  # the last: shape (2,) against (3,)
        with pytest.raises(thzmap.ArgumentError, match="distance_m: expected"):
            air.transmittance(f, bad)
    with pytest.raises(thzmap.Error, match=r"frequency_thz: 2 THz lies outside the range of "
                       r"atmosphere model 'itu-p676' \(0\.001 to 1 THz\)"):
        thzmap.atmosphere("itu-p676").attenuation_per_m(2.0)  # 1-1000 GHz only (not "2 to 2 THz")
    with pytest.raises(thzmap.Error, match="0.5 to 2 THz leaves the range"):
        thzmap.atmosphere("itu-p676").attenuation_per_m([0.5, 2.0])
    # text is not a frequency or a temperature (numpy read "0.5" as 0.5)
    for bad in ("0.5", ["0.3", "0.4"], True):
        with pytest.raises(thzmap.ArgumentError, match="frequency_thz: expected a number"):
            thzmap.atmosphere().attenuation_per_m(bad)
    with pytest.raises(thzmap.ArgumentError, match="temperature_k: expected a number"):
        thzmap.planck_radiance(0.5, "300")
    with pytest.raises(thzmap.ArgumentError, match="only for the lines model"):
        thzmap.atmosphere("itu-p676", h2o_lines="x.par")
    # a humidity that is no number is named by its argument, not by the library's kind of
    # humidity ("relative: expected a finite number" was what relative_humidity=nan said)
    for name in ("relative_humidity", "water_vapour_g_m3", "h2o_vmr"):
        for bad in (float("nan"), "0.5"):
            with pytest.raises(thzmap.ArgumentError, match=f"^{name}: expected a finite number"):
                thzmap.atmosphere(**{name: bad})
