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
    assert [c.type for c in mesh.cells] == ["vertex"]
    assert len(mesh.cells[0].data) == 300
    np.testing.assert_array_equal(mesh.point_data["arrival"].ravel(), np.arange(300))


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
