"""subfit.torch: gradcheck of LimitSurface, imls and arap; the Adam IMLS + ARAP loop."""

import sys

import numpy as np
import pytest

from conftest import REPO, ellipsoid_cloud, need


@pytest.fixture(scope="module")
def torch():
    return need("torch")


@pytest.fixture(scope="module")
def st(torch):
    import subfit.torch as st

    return st


def octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return v, f


def test_limit_surface_matches_surface_and_gradchecks(torch, st):
    import subfit

    v, f = octahedron()
    layer = st.LimitSurface(f, "loop", level=2)
    x = torch.tensor(v, dtype=torch.float64, requires_grad=True)
    y = layer(x)
    np.testing.assert_allclose(y.detach().numpy(), subfit.Surface(v, f).sample(2), atol=1e-12)
    assert torch.autograd.gradcheck(layer, (x,))
    xb = torch.randn(2, 6, 3, dtype=torch.float64, requires_grad=True)
    assert layer(xb).shape == (2, layer.num_samples, 3)
    assert torch.autograd.gradcheck(layer, (xb,))
    assert torch.autograd.gradgradcheck(layer, (x,))
    y32 = layer(x.detach().float())
    assert y32.dtype == torch.float32
    np.testing.assert_allclose(y32.numpy(), y.detach().numpy(), atol=1e-5)
    # Casting the module does not round its operator.
    layer.float()
    np.testing.assert_allclose(layer(x).detach().numpy(), y.detach().numpy(), rtol=0, atol=1e-15)


def test_limit_surface_catmull_clark_gradcheck(torch, st):
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    q = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
    layer = st.LimitSurface(q, "catmull-clark", level=1)
    x = torch.tensor(v, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(layer, (x,))
    assert layer.sample_faces.shape[1] == 4
    with pytest.raises(ValueError, match="shape"):
        layer(torch.zeros(7, 3, dtype=torch.float64))


def imls_reference(x, p, n, h):
    """Eq. 2–3 of Xie et al. 2023 directly, dense, in numpy."""
    d = x[:, None, :] - p[None, :, :]
    r2 = (d**2).sum(-1)
    phi = np.where(r2 < h * h, (1 - r2 / (h * h)) ** 4, 0.0)
    return (phi * (d * n[None]).sum(-1)).sum(1) / phi.sum(1)


def test_imls_values_and_gradcheck(torch, st):
    p, n = ellipsoid_cloud(3000, seed=11)
    rng = np.random.default_rng(12)
    x = p[:40] * 1.03 + rng.normal(scale=0.005, size=(40, 3))
    h = 0.12
    ref = imls_reference(x, p, n, h)
    xt = torch.tensor(x, dtype=torch.float64, requires_grad=True)
    got = st.imls(xt, p, n, h)
    np.testing.assert_allclose(got.detach().numpy(), ref, atol=1e-12)
    field = st.IMLS(torch.tensor(p), torch.tensor(n), h)
    assert torch.autograd.gradcheck(field, (xt,))
    assert torch.autograd.gradcheck(lambda s: st.imls(s, p, n, h), (xt[:5],))
    # Gradients reach the scan when its tensors require them (torch arithmetic over the
    # native neighbour lists); the values are the same.
    pt = torch.tensor(p[:400], requires_grad=True)
    nt = torch.tensor(n[:400] * 1.7, requires_grad=True)  # unnormalized: normalized inside
    xs = torch.tensor(p[:6] * 1.01, requires_grad=True)
    np.testing.assert_allclose(st.imls(xs, pt, nt, h).detach().numpy(),
                               st.imls(xs.detach(), p[:400], n[:400], h).numpy(), atol=1e-12)
    assert torch.autograd.gradcheck(lambda s, a, b: st.imls(s, a, b, h), (xs, pt, nt))


def test_arap_rigid_zero_and_gradcheck(torch, st):
    v, f = octahedron()
    rest = torch.tensor(v * [1.0, 0.8, 1.3])
    q, _ = torch.linalg.qr(torch.randn(3, 3, dtype=torch.float64, generator=torch.Generator().manual_seed(3)))
    if torch.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    rigid = rest @ q.T + torch.tensor([0.3, -1.0, 2.0], dtype=torch.float64)
    assert float(st.arap(rigid, rest, f)) < 1e-20
    x = (rest + 0.05 * torch.randn(6, 3, dtype=torch.float64, generator=torch.Generator().manual_seed(4))).requires_grad_()
    energy = st.ARAP(rest, f)
    assert energy(x).item() > 0
    assert torch.autograd.gradcheck(energy, (x,))
    assert energy(torch.stack([x, rigid])).shape == (2,)


def test_adam_imls_arap_loop_lowers_loss_tenfold(torch):
    sys.path.insert(0, str(REPO / "examples" / "python"))
    try:
        import torch_imls_arap
    finally:
        sys.path.pop(0)
    losses = torch_imls_arap.run(steps=300, verbose=False)
    assert min(losses) >= 0.0
    assert losses[-1] * 10 <= losses[0], (losses[0], losses[-1])


def test_docstring_examples_run(st, tmp_path, monkeypatch):
    # The examples of subfit.torch's docstrings (docs/python.md shows them) run as written.
    import doctest

    monkeypatch.chdir(tmp_path)
    tests = [t for t in doctest.DocTestFinder().find(st) if t.examples]
    assert len(tests) >= 6, [t.name for t in tests]
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for t in tests:
        runner.run(t)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed (printed above)"
