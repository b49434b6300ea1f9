import numpy as np
import proxima

def test_import():
    idx = proxima.Index(np.zeros((2, 3)), 1.0)
    assert idx.pairs().tolist() == [[0, 1]]
