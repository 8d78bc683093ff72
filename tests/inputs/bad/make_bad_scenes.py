#!/usr/bin/env python3
"""Writes the bad scene files of this directory and the table ../bad_scenes.tsv that
tests/cli/test_bad_scenes.sh checks: each scene breaks one rule of scene-format.md,
and `thzmap validate` must refuse it with exit status 2 and a message containing the
given text (the JSON path or line:column where there is one). Rerun after editing:
    python3 tests/inputs/bad/make_bad_scenes.py
"""
import copy
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))

BASE = {
    "format": "thzmap-scene/1",
    "channels": [{"frequency_thz": 0.35, "relative_width": 0.01}],
    "materials": {"wall": {"reflectivity": 0.1},
                  "paint": {"reflectivity": [[0.2, 0.05], [1.2, 0.12]]}},
    "objects": [
        {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
         "shape": {"type": "box", "size_m": [1, 1, 2], "inward": True}},
        {"name": "target", "type": "solid", "material": "paint", "temperature_k": 310,
         "shape": {"type": "cylinder", "radius_m": 0.1, "height_m": 0.75}},
    ],
    "sensors": [{"name": "cam", "position_m": [0, -0.45, 0.4], "look_at_m": [0, 0, 0.4],
                 "fov_deg": 40, "resolution": [16, 16]}],
}


def setp(doc, path, value):
    """Sets doc[path...] = value; value DELETE removes the key."""
    for key in path[:-1]:
        doc = doc[key]
    if value is DELETE:
        del doc[path[-1]]
    else:
        doc[path[-1]] = value


DELETE = object()

# (file, edits [(path, value)], expected substring); raw text instead of edits for
# syntax errors.
CASES = [
    ("syntax_missing_comma", '{\n  "format": "thzmap-scene/1"\n  "channels": []\n}\n', "syntax_missing_comma.json:3:12: invalid JSON"),
    ("syntax_nan", '{"format": "thzmap-scene/1",\n "x": NaN}\n', "syntax_nan.json:2:"),
    ("syntax_overflow", '{"format": "thzmap-scene/1",\n "x": 1e999}\n', "real number overflow"),
    ("syntax_duplicate_key", '{"format": "thzmap-scene/1",\n "format": "thzmap-scene/1"}\n',
     "duplicate object key"),
    ("syntax_empty", "", "invalid JSON"),
    ("not_an_object", "[1, 2, 3]\n", "expected a JSON object"),
    ("format_missing", [(["format"], DELETE)], "format: missing key"),
    ("format_wrong", [(["format"], "thzmap-scene/2")], "format: expected \"thzmap-scene/1\""),
    ("unknown_top_key", [(["photon"], {"per_channel": 10})], "photon: unknown key"),
    ("name_not_string", [(["name"], 5)], "name: expected a string, got a number"),
    ("channels_missing", [(["channels"], DELETE)], "channels: missing key"),
    ("channels_empty", [(["channels"], [])], "channels: expected at least one channel"),
    ("channel_negative_frequency", [(["channels", 0, "frequency_thz"], -0.3)],
     "channels[0].frequency_thz: expected a number > 0, got -0.3"),
    ("channel_zero_frequency", [(["channels", 0, "frequency_thz"], 0)],
     "channels[0].frequency_thz: expected a number > 0, got 0"),
    ("channel_frequency_string", [(["channels", 0, "frequency_thz"], "0.35")],
     "channels[0].frequency_thz: expected a number > 0, got a string"),
    ("channel_width_too_wide", [(["channels", 0, "relative_width"], 0.6)],
     "channels[0].relative_width: expected a number in (0, 0.5], got 0.6"),
    ("channel_width_zero", [(["channels", 0, "relative_width"], 0)],
     "channels[0].relative_width: expected a number in (0, 0.5]"),
    ("channel_unknown_key", [(["channels", 0, "width"], 0.1)], "channels[0].width: unknown key"),
    ("channel_range_count_zero",
     [(["channels"], {"from_thz": 0.2, "to_thz": 1.2, "count": 0, "relative_width": 0.01})],
     "channels.count: expected a whole number from 1"),
    ("channel_range_reversed",
     [(["channels"], {"from_thz": 1.2, "to_thz": 0.2, "count": 3, "relative_width": 0.01})],
     "channels.to_thz: expected a number > from_thz"),
    ("materials_missing", [(["materials"], DELETE)], "materials: missing key"),
    ("materials_empty", [(["materials"], {})], "materials: expected at least one material"),
    ("reflectivity_above_one", [(["materials", "wall", "reflectivity"], 1.5)],
     "materials.wall.reflectivity: expected a number in [0, 1], got 1.5"),
    ("reflectivity_negative", [(["materials", "wall", "reflectivity"], -0.1)],
     "materials.wall.reflectivity: expected a number in [0, 1], got -0.1"),
    ("reflectivity_table_point_above_one",
     [(["materials", "paint", "reflectivity"], [[0.2, 0.5], [0.4, 1.01]])],
     "materials.paint.reflectivity[1][1]: expected a number in [0, 1]"),
    ("table_frequencies_not_increasing",
     [(["materials", "paint", "reflectivity"], [[0.4, 0.05], [0.4, 0.12]])],
     "materials.paint.reflectivity[1][0]: frequencies must increase strictly"),
    ("table_frequency_negative",
     [(["materials", "paint", "reflectivity"], [[-0.4, 0.05], [0.4, 0.12]])],
     "materials.paint.reflectivity[0][0]: expected a number > 0"),
    ("table_not_pairs", [(["materials", "paint", "reflectivity"], [[0.2, 0.05, 1]])],
     "materials.paint.reflectivity[0]: expected a pair [frequency_thz, value]"),
    ("emissivity_plus_reflectivity_above_one", [(["materials", "wall", "emissivity"], 0.95)],
     "materials.wall.emissivity: emissivity + reflectivity must not exceed 1"),
    ("emissivity_plus_reflectivity_table",
     [(["materials", "paint", "emissivity"], [[0.1, 0.5], [1.0, 0.9]])],
     "materials.paint.emissivity: emissivity + reflectivity must not exceed 1"),
    ("material_unknown_key", [(["materials", "wall", "reflectance"], 0.1)],
     "materials.wall.reflectance: unknown key"),
    ("material_missing_reflectivity", [(["materials", "wall"], {"color": [1, 1, 1]})],
     "materials.wall.reflectivity: missing key"),
    ("material_color_out_of_range", [(["materials", "wall", "color"], [0.5, 1.5, 0])],
     "materials.wall.color[1]: expected a number in [0, 1], got 1.5"),
    ("material_color_short", [(["materials", "wall", "color"], [0.5, 0.5])],
     "materials.wall.color: expected a list of 3 numbers"),
    ("material_transmission_unknown", [(["materials", "wall", "transmission"], "specular")],
     "materials.wall.transmission: expected one of \"diffuse\", \"straight\""),
    ("material_attenuation_negative", [(["materials", "wall", "attenuation_per_m"], -1)],
     "materials.wall.attenuation_per_m: expected a number >= 0"),
    ("material_file_missing", [(["materials", "wall"], {"file": "materials/nope.csv"})],
     "materials.wall.file: "),
    ("material_file_bad_row", [(["materials", "wall"], {"file": "materials/bad_row.csv"})],
     "bad_row.csv:4: row 2, column 'reflectivity'"),
    ("material_file_unknown_column",
     [(["materials", "wall"], {"file": "materials/unknown_column.csv"})],
     "unknown_column.csv: unknown column 'reflectance'"),
    ("material_file_decreasing", [(["materials", "wall"], {"file": "materials/decreasing.csv"})],
     "decreasing.csv:3: row 2: frequencies must increase strictly"),
    ("material_file_out_of_range",
     [(["materials", "wall"], {"file": "materials/out_of_range.csv"})],
     "out_of_range.csv:3: row 2, column 'reflectivity': expected a number in [0, 1], got 1.2"),
    ("material_file_negative_alpha",
     [(["materials", "wall"], {"file": "materials/negative_alpha.csv", "reflectivity": 0.1})],
     "negative_alpha.csv:3: row 2, column 'attenuation_per_m'"),
    ("atmosphere_unknown_model", [(["atmosphere"], {"model": "fog"})],
     "atmosphere.model: expected one of"),
    ("atmosphere_constant_negative",
     [(["atmosphere"], {"model": "constant", "attenuation_per_m": -0.1})],
     "atmosphere.attenuation_per_m: expected a number >= 0"),
    ("atmosphere_constant_missing", [(["atmosphere"], {"model": "constant"})],
     "atmosphere.attenuation_per_m: missing key"),
    ("atmosphere_table_missing_file", [(["atmosphere"], {"model": "table", "file": "alpha.csv"})],
     "atmosphere.file: "),
    ("atmosphere_unknown_key", [(["atmosphere"], {"model": "none", "alpha": 1})],
     "atmosphere.alpha: unknown key"),
    ("objects_missing", [(["objects"], DELETE)], "objects: missing key"),
    ("objects_empty", [(["objects"], [])], "objects: expected at least one object"),
    ("object_negative_temperature", [(["objects", 1, "temperature_k"], -1)],
     "objects[1].temperature_k: expected a number >= 0, got -1"),
    ("object_temperature_string", [(["objects", 1, "temperature_k"], "hot")],
     "objects[1].temperature_k: expected a number >= 0, got a string"),
    ("object_temperature_missing", [(["objects", 1, "temperature_k"], DELETE)],
     "objects[1].temperature_k: missing key"),
    ("object_unknown_material", [(["objects", 1, "material"], "gold")],
     "objects[1].material: unknown material \"gold\""),
    ("object_duplicate_name", [(["objects", 1, "name"], "room")],
     "objects[1].name: object name \"room\" is already used"),
    ("object_unknown_key", [(["objects", 0, "temprature_k"], 300)],
     "objects[0].temprature_k: unknown key"),
    ("object_type_unknown", [(["objects", 0, "type"], "liquid")],
     "objects[0].type: expected one of \"solid\", \"shell\""),
    ("shell_without_thickness", [(["objects", 1, "type"], "shell")],
     "objects[1].thickness_m: missing key"),
    ("shell_zero_thickness", [(["objects", 1, "type"], "shell"), (["objects", 1, "thickness_m"], 0)],
     "objects[1].thickness_m: expected a number > 0, got 0"),
    ("solid_with_thickness", [(["objects", 1, "thickness_m"], 0.001)],
     "objects[1].thickness_m: only shells have a thickness"),
    ("two_sided_not_bool", [(["objects", 1, "two_sided"], "yes")],
     "objects[1].two_sided: expected true or false"),
    ("shape_missing", [(["objects", 0, "shape"], DELETE)], "objects[0].shape: missing key"),
    ("shape_unknown_type", [(["objects", 0, "shape"], {"type": "cone", "radius_m": 1})],
     "objects[0].shape.type: expected one of"),
    ("shape_unknown_key", [(["objects", 1, "shape", "radius"], 0.1)],
     "objects[1].shape.radius: unknown key"),
    ("box_negative_size", [(["objects", 0, "shape", "size_m"], [1, 1, -2])],
     "objects[0].shape.size_m[2]: expected a number > 0, got -2"),
    ("cylinder_two_segments", [(["objects", 1, "shape", "segments"], 2)],
     "objects[1].shape.segments: expected a whole number from 3"),
    ("cylinder_fractional_segments", [(["objects", 1, "shape", "segments"], 8.5)],
     "objects[1].shape.segments: expected a whole number from 3"),
    ("sphere_too_many_subdivisions",
     [(["objects", 1, "shape"], {"type": "sphere", "radius_m": 1, "subdivisions": 12})],
     "objects[1].shape.subdivisions: expected a whole number from 0 to 8"),
    ("disk_zero_radius", [(["objects", 1, "shape"], {"type": "disk", "radius_m": 0})],
     "objects[1].shape.radius_m: expected a number > 0, got 0"),
    ("mesh_file_missing", [(["objects", 1, "shape"], {"type": "mesh", "file": "nope.obj"})],
     "objects[1].shape.file: "),
    ("mesh_no_triangles",
     [(["objects", 1, "shape"], {"type": "mesh", "file": "../meshes/no_faces.obj"})],
     "no_faces.obj: the mesh has no triangles"),
    ("mesh_garbage", [(["objects", 1, "shape"], {"type": "mesh", "file": "../meshes/garbage.obj"})],
     "objects[1].shape.file: "),
    ("transform_zero_scale", [(["objects", 1, "transform"], {"scale": [1, 0, 1]})],
     "objects[1].transform.scale: a scale factor of 0"),
    ("transform_huge_scale", [(["objects", 1, "transform"], {"scale": 1e300})],
     "objects[1].transform: the object's coordinates or area exceed"),
    ("transform_unknown_key", [(["objects", 1, "transform"], {"rotate": [0, 0, 90]})],
     "objects[1].transform.rotate: unknown key"),
    ("transform_short_vector", [(["objects", 1, "transform"], {"translate_m": [0, 1]})],
     "objects[1].transform.translate_m: expected a list of 3 numbers"),
    ("sensors_missing", [(["sensors"], DELETE)], "sensors: missing key"),
    ("sensors_empty", [(["sensors"], [])], "sensors: expected at least one sensor"),
    ("sensor_fov_180", [(["sensors", 0, "fov_deg"], 180)],
     "sensors[0].fov_deg: expected a number in (0, 180), got 180"),
    ("sensor_fov_zero", [(["sensors", 0, "fov_deg"], 0)],
     "sensors[0].fov_deg: expected a number in (0, 180), got 0"),
    ("sensor_up_parallel", [(["sensors", 0, "up"], [0, 2, 0])],
     "sensors[0].up: the up vector is parallel to the viewing direction"),
    ("sensor_resolution_zero", [(["sensors", 0, "resolution"], [0, 16])],
     "sensors[0].resolution: expected [columns, rows]"),
    ("sensor_resolution_too_large", [(["sensors", 0, "resolution"], [65537, 16])],
     "sensors[0].resolution: expected [columns, rows], whole numbers from 1 to 65536"),
    ("sensor_resolution_beyond_memory",
     [(["channels"], {"from_thz": 0.2, "to_thz": 1.2, "count": 400, "relative_width": 0.01}),
      (["sensors", 0, "resolution"], [65536, 65536])],
     "sensors[0].resolution: the images of 65536 x 65536 pixels in 400 channels need"),
    ("sensor_look_at_self", [(["sensors", 0, "look_at_m"], [0, -0.45, 0.4])],
     "sensors[0].look_at_m: the point to look at is the sensor's position"),
    ("sensor_both_directions", [(["sensors", 0, "direction"], [0, 1, 0])],
     "sensors[0].direction: give either look_at_m or direction, not both"),
    ("sensor_no_direction", [(["sensors", 0, "look_at_m"], DELETE)],
     "sensors[0]: missing key 'look_at_m' or 'direction'"),
    ("sensor_zero_direction",
     [(["sensors", 0, "look_at_m"], DELETE), (["sensors", 0, "direction"], [0, 0, 0])],
     "sensors[0].direction: expected a non-zero direction"),
    ("sensor_duplicate_name",
     [(["sensors", 1], {"name": "cam", "position_m": [0, 0, 1], "direction": [0, 1, 0],
                        "fov_deg": 30, "resolution": [4, 4]})],
     "sensors[1].name: sensor name \"cam\" is already used"),
    ("sensor_aperture_zero", [(["sensors", 0, "aperture_m2"], 0)],
     "sensors[0].aperture_m2: expected a number > 0, got 0"),
    ("sensor_oversampling_zero", [(["sensors", 0, "oversampling"], 0)],
     "sensors[0].oversampling: expected a whole number from 1 to 16, got 0"),
    ("sensor_oversampling_17", [(["sensors", 0, "oversampling"], 17)],
     "sensors[0].oversampling: expected a whole number from 1 to 16, got 17"),
    ("sensor_normalize_zero", [(["sensors", 0, "normalize_to_k"], 0)],
     "sensors[0].normalize_to_k: expected a number > 0, got 0"),
    ("sensor_missing_name", [(["sensors", 0, "name"], DELETE)], "sensors[0].name: missing key"),
    ("photons_zero", [(["photons"], {"per_channel": 0})],
     "photons.per_channel: expected a whole number from 1"),
    ("photons_fractional", [(["photons"], {"per_channel": 1.5})],
     "photons.per_channel: expected a whole number from 1"),
    ("photons_gather_min_one", [(["photons"], {"gather_min_photons": 1})],
     "photons.gather_min_photons: expected a whole number from 2"),
    ("photons_min_power_one", [(["photons"], {"min_relative_power": 1})],
     "photons.min_relative_power: expected a number in [0, 1), got 1"),
    ("photons_negative_seed", [(["photons"], {"seed": -1})],
     "photons.seed: expected a whole number from 0"),
    ("photons_unknown_key", [(["photons"], {"count": 10})], "photons.count: unknown key"),
    ("render_unknown_integrator", [(["render"], {"integrator": "raytrace"})],
     "render.integrator: expected one of \"photon-map\", \"final-gather\", \"path\""),
    ("render_zero_gather_rays", [(["render"], {"gather_rays": 0})],
     "render.gather_rays: expected a whole number from 1"),
    # sensor optics and noise (format 1.1)
    ("sensor_psf_airy_without_diameter", [(["sensors", 0, "psf"], "airy")],
     "sensors[0].psf: \"airy\" needs the aperture"),
    ("sensor_psf_unknown", [(["sensors", 0, "psf"], "bessel")],
     "sensors[0].psf: expected one of \"none\", \"airy\", \"gaussian\""),
    ("sensor_psf_gaussian_without_fwhm", [(["sensors", 0, "psf"], "gaussian")],
     "sensors[0].psf_fwhm_deg: missing key"),
    ("sensor_psf_fwhm_without_gaussian", [(["sensors", 0, "psf_fwhm_deg"], 1.0)],
     "sensors[0].psf_fwhm_deg: psf_fwhm_deg is for \"psf\": \"gaussian\" only"),
    ("sensor_aperture_diameter_zero", [(["sensors", 0, "aperture_diameter_m"], 0)],
     "sensors[0].aperture_diameter_m: expected a number > 0"),
    ("sensor_noise_both_forms",
     [(["sensors", 0, "noise"], {"netd_k": 0.3, "integration_time_s": 0.01})],
     "sensors[0].noise: give either netd_k or the radiometer form"),
    ("sensor_noise_empty", [(["sensors", 0, "noise"], {})],
     "sensors[0].noise: expected {\"netd_k\": x}"),
    ("sensor_noise_netd_negative", [(["sensors", 0, "noise"], {"netd_k": -1})],
     "sensors[0].noise.netd_k: expected a NETD in K (> 0)"),
    ("sensor_noise_netd_list_length", [(["sensors", 0, "noise"], {"netd_k": [0.1, 0.2]})],
     "sensors[0].noise.netd_k: expected one value per channel (1), got 2"),
    ("sensor_noise_radiometer_missing",
     [(["sensors", 0, "noise"], {"receiver_temperature_k": 300, "integration_time_s": 0.01})],
     "sensors[0].noise.radiometer: missing key"),
    ("sensor_noise_radiometer_unknown",
     [(["sensors", 0, "noise"], {"receiver_temperature_k": 300, "integration_time_s": 0.01,
                                 "radiometer": "hybrid"})],
     "sensors[0].noise.radiometer: expected one of \"total-power\", \"dicke\""),
    ("sensor_noise_tau_zero",
     [(["sensors", 0, "noise"], {"receiver_temperature_k": 300, "integration_time_s": 0,
                                 "radiometer": "dicke"})],
     "sensors[0].noise.integration_time_s: expected a number > 0"),
    ("sensor_noise_unknown_key", [(["sensors", 0, "noise"], {"netd": 0.3})],
     "sensors[0].noise.netd: unknown key"),
    ("sensor_noise_seed_negative", [(["sensors", 0, "noise_seed"], -1)],
     "sensors[0].noise_seed: expected a whole number"),
]


def main():
    rows = ["# file\texit status\tthe message must contain (written by make_bad_scenes.py)"]
    for name, edits, expect in CASES:
        path = os.path.join(HERE, name + ".json")
        if isinstance(edits, str):
            text = edits
        else:
            doc = copy.deepcopy(BASE)
            for p, v in edits:
                if p[0] == "sensors" and len(p) == 2 and p[1] == len(doc["sensors"]):
                    doc["sensors"].append(v)
                    continue
                setp(doc, p, v)
            text = json.dumps(doc, indent=2) + "\n"
        with open(path, "w") as f:
            f.write(text)
        rows.append("%s.json\t2\t%s" % (name, expect))
    with open(os.path.join(HERE, "..", "bad_scenes.tsv"), "w") as f:
        f.write("\n".join(rows) + "\n")
    print("%d bad scenes" % len(CASES))


if __name__ == "__main__":
    main()
