import pytest

from plateqp.linalg import Cholesky, bindings


@pytest.fixture
def seam_cholesky() -> Cholesky:
    """A fresh factor through CHOLMOD's C API inside cvxopt's wheels (skipped where there is none)."""
    if "cvxopt" not in bindings():
        pytest.skip("cvxopt's CHOLMOD is not installed")
    chol = Cholesky("cvxopt")
    if chol.direct is None:
        pytest.skip("CHOLMOD's C API is not reachable here")
    return chol
