#!/usr/bin/env python3
"""Tells materials apart by their THz spectra: a scikit-learn classifier trained on the
pixels of a simulated teraeye image, with the material of the object each pixel sees
(from the object_id truth map) as the label. Prints the accuracy on held-out pixels.

    PYTHONPATH=python python3 examples/python/classify_pixels.py [--small]

--small (or THZMAP_EXAMPLE_SMALL=1) renders 24 x 24 pixels, for tests.
"""
import argparse
import json
import os

import numpy as np
import thzmap
from sklearn.ensemble import RandomForestClassifier
from sklearn.metrics import accuracy_score, confusion_matrix
from sklearn.model_selection import train_test_split

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE_DIR = os.path.join(HERE, "..", "teraeye")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--small", action="store_true",
                    default=os.environ.get("THZMAP_EXAMPLE_SMALL") == "1")
    args = ap.parse_args()

    with open(os.path.join(SCENE_DIR, "scene.json")) as f:
        d = json.load(f)
    if args.small:
        d["sensors"][0]["resolution"] = [24, 24]
        d["sensors"][0]["oversampling"] = 1
    scene = thzmap.scene_from_dict(d, base_dir=SCENE_DIR)
    image = thzmap.simulate(scene, integrator="path", seed=2).image(scene.sensor_names[0])

    # Features: each pixel's normalised spectrum, which removes most of the temperature
    # and keeps the material's shape; labels: the material of the object it sees.
    hit = image.object_id >= 0
    features = image.normalized[hit]  # (pixels, channels)
    material_of_object = np.array([o.material_name for o in scene.objects])
    labels = material_of_object[image.object_id[hit].astype(int)]

    names, counts = np.unique(labels, return_counts=True)
    stratify = labels if counts.min() >= 2 else None
    x_train, x_test, y_train, y_test = train_test_split(
        features, labels, test_size=0.3, random_state=0, stratify=stratify)
    clf = RandomForestClassifier(n_estimators=100, random_state=0)
    clf.fit(x_train, y_train)
    predicted = clf.predict(x_test)

    print(f"{features.shape[0]} pixels, {features.shape[1]} channels, classes: " +
          ", ".join(f"{n} ({c})" for n, c in zip(names, counts)))
    print("confusion matrix (rows: truth, columns: predicted, order as above):")
    print(confusion_matrix(y_test, predicted, labels=names))
    print(f"accuracy: {accuracy_score(y_test, predicted):.3f} on {len(y_test)} held-out pixels")


if __name__ == "__main__":
    main()
