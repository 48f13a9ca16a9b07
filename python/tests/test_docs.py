"""The MONAI-style transform of docs/PYTHON.md, run as written on numpy data (MONAI and torch are
not installed here: a MetaTensor's .affine and .detach() paths are not exercised)."""

import os
import re
import unittest

import numpy as np

import segmesh
from support import HERE, data

try:
    import nibabel
except ImportError:
    nibabel = None


def doc_example(marker):
    with open(os.path.join(HERE, "..", "..", "docs", "PYTHON.md")) as f:
        blocks = re.findall(r"```python\n(.*?)```", f.read(), re.S)
    return next(b for b in blocks if marker in b)


@unittest.skipIf(nibabel is None, "nibabel is not installed (Debian: python3-nibabel)")
class MonaiTransform(unittest.TestCase):
    def test_transform_meshes_a_channel_first_c_ordered_prediction(self):
        namespace = {}
        exec(doc_example("class MeshLabelsd"), namespace)
        seg = nibabel.load(data("totalsegmentator", "example_seg.nii.gz"))
        pred = np.ascontiguousarray(np.asarray(seg.dataobj)[None])  # [1, H, W, D], as torch has it
        out = namespace["MeshLabelsd"]("pred", labels=[5, 52])(
            {"pred": pred, "pred_meta_dict": {"affine": seg.affine}})
        expected = segmesh.mesh(seg, labels=[5, 52])
        self.assertEqual([p.name for p in out["pred_meshes"]], [p.name for p in expected])
        for p, q in zip(out["pred_meshes"], expected):
            np.testing.assert_array_equal(p.vertices, q.vertices)
            self.assertTrue(p.measures["closed"])


if __name__ == "__main__":
    unittest.main()
