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
    ("syntax_missing_comma", '{\n  "format": "thzmap-scene/1"\n  "channels": []\n}\n', "syntax_missing_comma.json:3:3: invalid JSON: '}' expected near '\"channels\"'"),
    ("syntax_nan", '{"format": "thzmap-scene/1",\n "x": NaN}\n', "syntax_nan.json:2:7: invalid"),
    ("syntax_overflow", '{"format": "thzmap-scene/1",\n "x": 1e999}\n',
     "syntax_overflow.json:2:7: invalid JSON: real number overflow near '1e999' (a number beyond what JSON's numbers hold here"),
    ("syntax_big_integer", '{"format": "thzmap-scene/1",\n "photons": {"per_channel": '
     '18446744073709551616}}\n', "syntax_big_integer.json:2:29: invalid JSON: too big integer"
     " near '18446744073709551616' (a number beyond what JSON's numbers hold here: whole "
     "numbers up to 9223372036854775807"),
    ("syntax_duplicate_key", '{"format": "thzmap-scene/1",\n "format": "thzmap-scene/1"}\n',
     "duplicate object key"),
    ("syntax_empty", "", "syntax_empty.json:1:1: invalid JSON: '[' or '{' expected near end of "
     "file (the file is empty)"),
    # a UTF-8 byte-order mark is read past (RFC 8259): the document's own error follows
    ("syntax_bom", '\ufeff{"format": "thzmap-scene/1"}\n', "channels: missing key"),
    # saved as UTF-16 (its byte-order mark first): not said to be empty, as it was
    ("syntax_utf16", '{"format": "thzmap-scene/1"}\n'.encode("utf-16"),
     "syntax_utf16.json:1:1: invalid JSON: unable to decode byte 0xff (JSON is UTF-8 text: was "
     "the file saved in another encoding, such as UTF-16?)"),
    ("not_an_object", "[1, 2, 3]\n", "expected a JSON object"),
    ("format_missing", [(["format"], DELETE)], "format: missing key"),
    ("format_wrong", [(["format"], "thzmap-scene/2")], "format: expected \"thzmap-scene/1\""),
    ("unknown_top_key", [(["photon"], {"per_channel": 10})], "photon: unknown key"),
    ("name_not_string", [(["name"], 5)], "name: expected a string, got a number"),
    ("channels_missing", [(["channels"], DELETE)], "channels: missing key"),
    ("channels_empty", [(["channels"], [])], "channels: expected at least one channel"),
    ("channel_negative_frequency", [(["channels", 0, "frequency_thz"], -0.3)],
     "channels[0].frequency_thz: expected a number in (0, 10000], got -0.3"),
    ("channel_zero_frequency", [(["channels", 0, "frequency_thz"], 0)],
     "channels[0].frequency_thz: expected a number in (0, 10000], got 0"),
    ("channel_frequency_string", [(["channels", 0, "frequency_thz"], "0.35")],
     "channels[0].frequency_thz: expected a number in (0, 10000], got a string"),
    ("channel_frequency_too_high", [(["channels", 0, "frequency_thz"], 1e300)],
     "channels[0].frequency_thz: expected a number in (0, 10000], got 1e+300"),
    ("channel_range_too_high",
     [(["channels"], {"from_thz": 0.2, "to_thz": 2e4, "count": 3, "relative_width": 0.01})],
     "channels.to_thz: expected a number in (0, 10000], got 20000"),
    ("channel_response_too_high",
     [(["format"], "thzmap-scene/1.1"),
      (["channels", 0], {"response": [[0.34, 1], [2e4, 1]]})],
     "channels[0]: expected a response that is 0 above 10000 THz (the frequencies' limit), it "
     "is > 0 up to 20000 THz"),
    ("channel_width_too_wide", [(["channels", 0, "relative_width"], 0.6)],
     "channels[0].relative_width: expected a number in (0, 0.5], got 0.6"),
    ("channel_width_just_too_wide", [(["channels", 0, "relative_width"], 0.5000001)],
     "channels[0].relative_width: expected a number in (0, 0.5], got 0.5000001"),
    ("channel_width_zero", [(["channels", 0, "relative_width"], 0)],
     "channels[0].relative_width: expected a number in (0, 0.5]"),
    ("channel_unknown_key", [(["channels", 0, "width"], 0.1)], "channels[0].width: unknown key"),
    ("channel_range_count_zero",
     [(["channels"], {"from_thz": 0.2, "to_thz": 1.2, "count": 0, "relative_width": 0.01})],
     "channels.count: expected a whole number from 1"),
    ("channel_range_reversed",
     [(["channels"], {"from_thz": 1.2, "to_thz": 0.2, "count": 3, "relative_width": 0.01})],
     "channels.to_thz: expected a number > from_thz"),
    # an evenly spaced range needs distinct ends (to_thz == from_thz with count 2 gave two
    # channels at one frequency), and count 1 a single one (to_thz != from_thz was taken)
    ("channel_range_same_ends",
     [(["channels"], {"from_thz": 0.35, "to_thz": 0.35, "count": 2, "relative_width": 0.01})],
     "channels.to_thz: expected a number > from_thz (0.35), got 0.35"),
    ("channel_range_one_two_ends",
     [(["channels"], {"from_thz": 0.35, "to_thz": 0.5, "count": 1, "relative_width": 0.01})],
     "channels.to_thz: with count 1, to_thz must equal from_thz (0.35)"),
    # frequency_thz beside a measured response lies where the response is > 0: above its
    # top as well as below its bottom
    ("channel_frequency_above_response",
     [(["channels", 0], {"frequency_thz": 0.4, "response": [[0.34, 1], [0.36, 1]]})],
     "channels[0].frequency_thz: expected a frequency where the response is > 0 (0.34 to "
     "0.36 THz), got 0.4"),
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
    # eps + R checked at the emissivity table's own points: its peak at 0.5 THz (0.95 + 0.1)
    # lies between none of R's (a constant), and not at 1 THz either
    ("emissivity_table_peak",
     [(["materials", "wall", "emissivity"], [[0.2, 0.3], [0.5, 0.95], [1.0, 0.3]])],
     "materials.wall.emissivity: emissivity + reflectivity must not exceed 1, got 0.95 + 0.1 "
     "= 1.05 at 0.5 THz"),
    ("emissivity_plus_index_reflectance",
     [(["format"], "thzmap-scene/1.1"),
      (["materials", "wall"], {"refractive_index": [10, 0], "emissivity": 0.5})],
     "materials.wall.emissivity: emissivity + the hemispherical mean reflectance of the "
     "material's complex index must not exceed 1, got 0.5 + 0.640"),
    ("index_huge",
     [(["format"], "thzmap-scene/1.1"), (["materials", "wall"], {"refractive_index": [1e300, 1e300]})],
     "materials.wall.refractive_index[0]: expected a number in (0, 1e+100], got 1e+300"),
    ("index_k_huge",
     [(["format"], "thzmap-scene/1.1"), (["materials", "wall"], {"refractive_index": [1e-300, 1e300]})],
     "materials.wall.refractive_index[1]: expected a number in [0, 1e+100], got 1e+300"),
    ("index_table_k_huge",
     [(["format"], "thzmap-scene/1.1"),
      (["materials", "wall"], {"refractive_index": [[0.2, 2, 1], [0.4, 2, 1e300]]})],
     "materials.wall.refractive_index[1][2]: expected a number in [0, 1e+100], got 1e+300"),
    ("index_file_k_huge",
     [(["format"], "thzmap-scene/1.1"), (["materials", "wall"], {"file": "materials/huge_k.csv"})],
     "huge_k.csv:3: row 2, column 'k': expected a number in [0, 1e+100], got 1e+300"),
    ("debye_eps_huge",
     [(["format"], "thzmap-scene/1.1"),
      (["materials", "wall"], {"permittivity_model": {"model": "debye", "eps_inf": 1,
                                                      "eps_s": 1e300, "tau_ps": 1e300}})],
     "materials.wall.permittivity_model.eps_s: expected a number in [1, 1e+200], got 1e+300"),
    ("debye_overflows",
     [(["format"], "thzmap-scene/1.1"),
      (["materials", "wall"], {"permittivity_model": {"model": "debye", "eps_inf": 1,
                                                      "eps_s": 1e200, "tau_ps": 1e300}})],
     "materials.wall.permittivity_model: the complex index of material \"wall\" at 0.35 THz "
     "(channel \"0.350 THz\") is n = "),
    ("lorentz_overflows",
     [(["format"], "thzmap-scene/1.1"),
      (["materials", "wall"], {"permittivity_model": {
          "model": "lorentz", "eps_inf": 1,
          "oscillators": [{"frequency_thz": 0.35, "strength": 1e300, "width_thz": 1e-300}]}})],
     "materials.wall.permittivity_model: the complex index of material \"wall\" at 0.35 THz"),
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
    # a table's frequencies increase strictly (a repeated one is a step of no width) and are > 0
    ("material_file_repeated_frequency",
     [(["materials", "wall"], {"file": "materials/repeated_frequency.csv"})],
     "repeated_frequency.csv:4: row 2: frequencies must increase strictly, got 0.4 THz after "
     "0.4 THz"),
    ("material_file_zero_frequency",
     [(["materials", "wall"], {"file": "materials/zero_frequency.csv"})],
     "zero_frequency.csv:2: row 1, column 'frequency_thz': expected a number > 0, got 0"),
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
     "atmosphere.attenuation_per_m: expected a number in [0, 1e+10], got -0.1"),
    ("atmosphere_constant_missing", [(["atmosphere"], {"model": "constant"})],
     "atmosphere.attenuation_per_m: missing key"),
    # the air of itu-p676 and lines (scene-format.md, "atmosphere"): each bound, and one
    # humidity key only (two were taken, the last winning)
    ("atmosphere_air_too_warm",
     [(["atmosphere"], {"model": "itu-p676", "temperature_k": 450, "pressure_hpa": 1013.25,
                        "relative_humidity": 0.5})],
     "atmosphere.temperature_k: expected a number in [100, 400], got 450"),
    ("atmosphere_zero_pressure",
     [(["atmosphere"], {"model": "itu-p676", "temperature_k": 290, "pressure_hpa": 0,
                        "relative_humidity": 0.5})],
     "atmosphere.pressure_hpa: expected a number in (0, 2000], got 0"),
    # a channel just above itu-p676's 1 THz: the refusal names the model that covers it
    ("atmosphere_itu_above_1thz",
     [(["channels", 0, "frequency_thz"], 1.05),
      (["atmosphere"], {"model": "itu-p676", "temperature_k": 295, "pressure_hpa": 1013.25,
                        "relative_humidity": 0.5})],
     "leaves the range of atmosphere model 'itu-p676' (0.001 to 1 THz); model 'lines' covers "
     "0.001 to 15 THz"),
    # a GHz value given in THz (350 for 0.35) with humid air: the refusal of the band beyond
    # the model's range says what validate's warning about channels beyond 10 THz would
    # have said, which it hides (it named only the model's range)
    ("atmosphere_ghz_as_thz",
     [(["channels", 0, "frequency_thz"], 350),
      (["atmosphere"], {"model": "itu-p676", "temperature_k": 295, "pressure_hpa": 1013.25,
                        "relative_humidity": 0.5})],
     "atmosphere: channel '350.000 THz' band (centre +- 6 sigma): 341.082 to 358.918 THz leaves "
     "the range of atmosphere model 'itu-p676' (0.001 to 1 THz); channel \"350.000 THz\" is at "
     "350 THz, beyond the 0.05 to 10 THz thzmap's models are meant for: frequency_thz is in THz "
     "(350 GHz = 0.35 THz)"),
    ("atmosphere_vmr_one",
     [(["atmosphere"], {"model": "itu-p676", "temperature_k": 290, "pressure_hpa": 1013.25,
                        "h2o_vmr": 1})],
     "atmosphere.h2o_vmr: expected a number in [0, 1), got 1"),
    ("atmosphere_two_humidities",
     [(["atmosphere"], {"model": "itu-p676", "temperature_k": 290, "pressure_hpa": 1013.25,
                        "relative_humidity": 0.5, "h2o_vmr": 0.01})],
     "atmosphere.h2o_vmr: give only one of relative_humidity, water_vapour_g_m3, h2o_vmr "
     "(relative_humidity is given too)"),
    ("atmosphere_table_missing_file", [(["atmosphere"], {"model": "table", "file": "alpha.csv"})],
     "atmosphere.file: "),
    ("atmosphere_constant_too_large",
     [(["atmosphere"], {"model": "constant", "attenuation_per_m": 1e200})],
     "atmosphere.attenuation_per_m: expected a number in [0, 1e+10], got 1e+200"),
    ("atmosphere_table_too_large",
     [(["atmosphere"], {"model": "table", "file": "materials/huge_air_alpha.csv"})],
     "huge_air_alpha.csv:3: row 2, column 'attenuation_per_m': expected a number in "
     "[0, 1e+10], got 1e+200"),
    ("atmosphere_extent_too_far",
     [(["atmosphere"], {"model": "constant", "attenuation_per_m": 0.05,
                        "extent_min_m": [-1e300, -1, -1], "extent_max_m": [1, 1, 3]})],
     "atmosphere.extent_min_m[0]: expected a number in [-1e+09, 1e+09], got -1e+300"),
    ("atmosphere_unknown_key", [(["atmosphere"], {"model": "none", "alpha": 1})],
     "atmosphere.alpha: unknown key"),
    ("objects_missing", [(["objects"], DELETE)], "objects: missing key"),
    ("objects_empty", [(["objects"], [])], "objects: expected at least one object"),
    ("object_negative_temperature", [(["objects", 1, "temperature_k"], -1)],
     "objects[1].temperature_k: expected a number in [0, 1e+06], got -1"),
    ("object_temperature_string", [(["objects", 1, "temperature_k"], "hot")],
     "objects[1].temperature_k: expected a number in [0, 1e+06], got a string"),
    ("object_temperature_huge", [(["objects", 1, "temperature_k"], 4e38)],
     "objects[1].temperature_k: expected a number in [0, 1e+06], got 4e+38"),
    ("atmosphere_background_temperature_huge",
     [(["atmosphere"], {"model": "constant", "attenuation_per_m": 0.05,
                        "background_temperature_k": 1e300})],
     "atmosphere.background_temperature_k: expected a number in [0, 10000], got 1e+300"),
    ("sensor_normalize_too_cold", [(["sensors", 0, "normalize_to_k"], 0.1)],
     "sensors[0].normalize_to_k: expected a temperature >= 0.3427 K (h nu / k T_ref at most 50 "
     "at 0.357 THz"),
    # the floor is set by the channel whose band reaches highest (0.5 THz at 50 %: 1 THz,
    # h 1 THz / 50 k = 0.95985 K), not the highest centre (0.8 THz at 1 %: 0.816 THz,
    # 0.7832 K, which 0.95 K would pass)
    ("sensor_normalize_wide_band", [(["channels"], [{"frequency_thz": 0.5, "relative_width": 0.5},
                                                    {"frequency_thz": 0.8, "relative_width": 0.01}]),
                                    (["sensors", 0, "normalize_to_k"], 0.95)],
     "sensors[0].normalize_to_k: expected a temperature >= 0.9599 K (h nu / k T_ref at most 50 "
     "at 1 THz, the top of channel \"0.500 THz\"'s band"),
    # a GHz value given in THz (350 for 0.35) with normalize_to_k given: the refusal says
    # what the warning about channels beyond 10 THz would have said, which it hides
    ("sensor_normalize_ghz_as_thz", [(["channels", 0, "frequency_thz"], 350),
                                     (["sensors", 0, "normalize_to_k"], 295)],
     "sensors[0].normalize_to_k: expected a temperature >= 342.7 K (h nu / k T_ref at most "
     "50 at 357 THz, the top of channel \"350.000 THz\"'s band; colder, B(T_ref) is too "
     "small for the normalised cube), got 295 K; channel \"350.000 THz\" is at 350 THz, "
     "beyond the 0.05 to 10 THz thzmap's models are meant for: frequency_thz is in THz "
     "(350 GHz = 0.35 THz)"),
    ("sensor_normalize_huge", [(["sensors", 0, "normalize_to_k"], 1e300)],
     "sensors[0].normalize_to_k: expected a number in (0, 1e+06], got 1e+300"),
    ("sensor_noise_receiver_temperature_huge",
     [(["sensors", 0, "noise"], {"receiver_temperature_k": 1e300, "integration_time_s": 0.01,
                                 "radiometer": "dicke"})],
     "sensors[0].noise.receiver_temperature_k: expected a number in [0, 1e+06], got 1e+300"),
    ("object_temperature_missing", [(["objects", 1, "temperature_k"], DELETE)],
     "objects[1].temperature_k: missing key"),
    # the scene's materials listed; a library entry of that name: how to take it
    ("object_unknown_material", [(["objects", 1, "material"], "gold")],
     'objects[1].material: unknown material "gold" (the scene\'s materials: wall, paint); the '
     'material library has one of that name: define it in "materials" as "gold": {"library": "gold"}'),
    ("object_unknown_material_typo", [(["objects", 1, "material"], "pain")],
     'objects[1].material: unknown material "pain" (the scene\'s materials: wall, paint)'),
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
    # a whole number written as a real is held to the range too
    ("cylinder_segments_real_too_many", [(["objects", 1, "shape", "segments"], 2e6)],
     "objects[1].shape.segments: expected a whole number from 3 to 1000000, got 2e+06"),
    # every size of every shape > 0 (a negative one mirrors the shape, turning its normals)
    ("cylinder_negative_height", [(["objects", 1, "shape", "height_m"], -0.75)],
     "objects[1].shape.height_m: expected a number > 0, got -0.75"),
    ("rectangle_negative_size",
     [(["objects", 1, "shape"], {"type": "rectangle", "size_m": [-1, 1]})],
     "objects[1].shape.size_m[0]: expected a number > 0, got -1"),
    # a mesh whose every triangle has its corners on one line has no surface
    ("mesh_no_area",
     [(["objects", 1, "shape"], {"type": "mesh", "file": "../meshes/no_area.obj"})],
     "objects[1].shape: the shape has no triangles of non-zero area"),
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
    ("sensor_same_files",
     [(["sensors", 0, "name"], "a/b"),
      (["sensors", 1], {"name": "a_b", "position_m": [0, 0, 1], "direction": [0, 1, 0],
                        "fov_deg": 30, "resolution": [4, 4]})],
     "sensors[1].name: \"a_b\" would write the same files as sensors[0] \"a/b\""),
    ("sensor_name_too_long", [(["sensors", 0, "name"], "c" * 201)],
     "sensors[0].name: a name of 201 bytes (expected at most 200"),
    ("sensor_aperture_zero", [(["sensors", 0, "aperture_m2"], 0)],
     "sensors[0].aperture_m2: expected a number in [1e-12, 1e+06], got 0"),
    ("sensor_oversampling_zero", [(["sensors", 0, "oversampling"], 0)],
     "sensors[0].oversampling: expected a whole number from 1 to 16, got 0"),
    ("sensor_oversampling_17", [(["sensors", 0, "oversampling"], 17)],
     "sensors[0].oversampling: expected a whole number from 1 to 16, got 17"),
    ("sensor_normalize_zero", [(["sensors", 0, "normalize_to_k"], 0)],
     "sensors[0].normalize_to_k: expected a number in (0, 1e+06], got 0"),
    ("sensor_missing_name", [(["sensors", 0, "name"], DELETE)], "sensors[0].name: missing key"),
    ("photons_zero", [(["photons"], {"per_channel": 0})],
     "photons.per_channel: expected a whole number from 1"),
    ("photons_fractional", [(["photons"], {"per_channel": 1.5})],
     "photons.per_channel: expected a whole number from 1"),
    ("photons_beyond_2_53", [(["photons"], {"per_channel": 9007199254740993})],
     "photons.per_channel: expected a whole number from 1 to 9007199254740992, got "
     "9007199254740993"),
    ("photons_seed_real_beyond_int64", [(["photons"], {"seed": 1e19})],
     "photons.seed: expected a whole number from 0 to 9223372036854775807, got 1e+19"),
    ("render_max_seconds_zero", [(["render"], {"target_noise_k": 0.1, "max_seconds": 0})],
     "render.max_seconds: expected a number > 0, got 0"),
    ("render_target_zero", [(["render"], {"target_noise_k": 0})],
     "render.target_noise_k: expected a number > 0, got 0"),
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
     "sensors[0].aperture_diameter_m: expected a number in [1e-06, 1000]"),
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
    ("sensor_aperture_too_large", [(["sensors", 0, "aperture_m2"], 1e7)],
     "sensors[0].aperture_m2: expected a number in [1e-12, 1e+06], got 1e+07"),
    ("sensor_aperture_too_small", [(["sensors", 0, "aperture_m2"], 1e-300)],
     "sensors[0].aperture_m2: expected a number in [1e-12, 1e+06], got 1e-300"),
    ("sensor_aperture_diameter_too_small",
     [(["format"], "thzmap-scene/1.1"), (["sensors", 0, "aperture_diameter_m"], 1e-170)],
     "sensors[0].aperture_diameter_m: expected a number in [1e-06, 1000], got 1e-170"),
    ("sensor_aperture_diameter_too_large",
     [(["format"], "thzmap-scene/1.1"), (["sensors", 0, "aperture_diameter_m"], 1e200)],
     "sensors[0].aperture_diameter_m: expected a number in [1e-06, 1000], got 1e+200"),
    ("object_too_far", [(["objects", 1, "transform"], {"translate_m": [0, 2e9, 0]})],
     "objects[1].transform: the object reaches 2e+09 m from the origin; scenes must lie "
     "within 1e+09 m of it"),
    ("object_too_far_negative", [(["objects", 1, "transform"], {"translate_m": [0, 0, -2e9]})],
     "objects[1].transform: the object reaches 2e+09 m from the origin; scenes must lie "
     "within 1e+09 m of it"),
    ("sensor_too_far", [(["sensors", 0, "position_m"], [0, -0.45, 1e30])],
     "sensors[0].position_m[2]: expected a number in [-1e+09, 1e+09], got 1e+30"),
    ("channel_response_huge",
     [(["format"], "thzmap-scene/1.1"),
      (["channels", 0], {"response": [[0.34, 1e308], [0.36, 1e308]]})],
     "channels[0]: the response's integrals (int g dnu = inf Hz"),
    ("channel_response_tiny",
     [(["format"], "thzmap-scene/1.1"),
      (["channels", 0], {"response": [[0.34, 1e-320], [0.36, 1e-320]]})],
     "channels[0]: the response's integrals (int g dnu = "),
    ("reflection_unknown", [(["materials", "wall", "reflection"], "glossy")],
     'materials.wall.reflection: expected "diffuse", "specular" or {"model": "ward", '
     '"alpha_x": ax, "alpha_y": ay}, got "glossy"'),
    ("reflection_ward_alpha",
     [(["materials", "wall", "reflection"], {"model": "ward", "alpha_x": 0, "alpha_y": 0.2})],
     "materials.wall.reflection.alpha_x"),
    ("reflection_ward_missing",
     [(["materials", "wall", "reflection"], {"model": "ward", "alpha_x": 0.2})],
     "materials.wall.reflection.alpha_y: missing key"),
    ("reflection_number", [(["materials", "wall", "reflection"], 3)],
     'materials.wall.reflection: expected "diffuse", "specular" or {"model": "ward"'),
]


def main():
    rows = ["# file\texit status\tthe message must contain (written by make_bad_scenes.py)"]
    for name, edits, expect in CASES:
        path = os.path.join(HERE, name + ".json")
        if isinstance(edits, (str, bytes)):
            text = edits
        else:
            doc = copy.deepcopy(BASE)
            for p, v in edits:
                if p[0] == "sensors" and len(p) == 2 and p[1] == len(doc["sensors"]):
                    doc["sensors"].append(v)
                    continue
                setp(doc, p, v)
            text = json.dumps(doc, indent=2) + "\n"
        with open(path, "wb" if isinstance(text, bytes) else "w") as f:
            f.write(text)
        rows.append("%s.json\t2\t%s" % (name, expect))
    with open(os.path.join(HERE, "..", "bad_scenes.tsv"), "w") as f:
        f.write("\n".join(rows) + "\n")
    print("%d bad scenes" % len(CASES))


if __name__ == "__main__":
    main()
