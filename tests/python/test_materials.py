"""Scene materials seen from Python: each material's reflection lobe (`reflection` in the
scene file) and Ward's slopes, as thz_scene_material reports them."""
import thzmap
from conftest import tiny_scene_dict


def test_reflection_lobes(tiny_dir):
    d = tiny_scene_dict()
    d["materials"]["wall"]["reflection"] = "specular"
    d["materials"]["paint"]["reflection"] = {"model": "ward", "alpha_x": 0.2, "alpha_y": 0.05}
    scene = thzmap.scene_from_dict(d, base_dir=tiny_dir)
    by_name = {m.name: m for m in scene.materials}
    assert by_name["wall"].reflection == "specular"
    assert by_name["paint"].reflection == "ward"
    assert (by_name["paint"].ward_alpha_x, by_name["paint"].ward_alpha_y) == (0.2, 0.05)
    assert by_name["cloth"].reflection == "diffuse"
    assert (by_name["cloth"].ward_alpha_x, by_name["cloth"].ward_alpha_y) == (0.0, 0.0)
