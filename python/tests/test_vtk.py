"""The binaries' VTK files (``--positions vtk``) read with meshio, the lightest Python reader,
and agree with the same run's NumPy positions."""

import numpy as np
import pytest

meshio = pytest.importorskip("meshio")


def test_dla_vtk_reads_with_meshio_and_matches_the_npy(cli):
    out, _ = cli.run("dla", "--particles", 300, "--seed", 3, "--positions", "vtk")
    mesh = meshio.read(out / "positions.vtk")
    xy = np.load(out / "positions.npy")
    assert mesh.points.shape == (300, 3)
    np.testing.assert_array_equal(mesh.points[:, :2], xy)
    assert np.all(mesh.points[:, 2] == 0.0)
    # The seed is a vertex; every other particle a line from its parent to it.
    parent = np.load(out / "positions_parent.npy")
    assert [c.type for c in mesh.cells] == ["vertex", "line"]
    np.testing.assert_array_equal(mesh.cells[0].data.ravel(), [0])
    lines = mesh.cells[1].data
    np.testing.assert_array_equal(lines[:, 1], np.arange(1, 300))
    np.testing.assert_array_equal(lines[:, 0], parent[1:])
    np.testing.assert_array_equal(mesh.point_data["arrival"].ravel(), np.arange(300))
    np.testing.assert_array_equal(mesh.point_data["parent"].ravel(), parent)
    # Each line joins touching particles.
    d = np.linalg.norm(xy[lines[:, 1]] - xy[lines[:, 0]], axis=1)
    np.testing.assert_allclose(d, 1.0, atol=1e-8)


@pytest.mark.parametrize(
    "program, flags, attribute",
    [
        ("dlca", ["--size", 32, "--fill", 0.1, "--target-clusters", 5], "cluster"),
        ("animat", ["--steps", 5, "--foxes", 10, "--rabbits", 40, "--start-radius", 20], "species"),
    ],
)
def test_lattice_and_animat_vtk_read_with_meshio(cli, program, flags, attribute):
    out, _ = cli.run(program, *flags, "--positions", "vtk")
    files = sorted(out.glob("*.vtk"))
    assert files, f"{program} wrote no .vtk file"
    mesh = meshio.read(files[-1])
    assert mesh.points.shape[1] == 3 and len(mesh.points) > 0
    assert [c.type for c in mesh.cells] == ["vertex"]
    assert len(mesh.cells[0].data) == len(mesh.points)
    assert attribute in mesh.point_data
