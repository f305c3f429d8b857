"""progress=True writes to sys.stderr; a callable gets (done, total), ending at the total."""

import aggsim


def test_callback_reaches_the_total():
    seen = []
    aggsim.dla(particles=3000, progress=lambda d, t: seen.append((d, t)))
    assert seen[-1] == (3000, 3000)
    seen.clear()
    lat = aggsim.DlcaLattice(64, 0.05, seed=1)
    lat.step(7, progress=lambda d, t: seen.append((d, t)))
    assert seen[-1] == (7, 7)
    seen.clear()
    aggsim.animat(steps=5, foxes=10, rabbits=40, start_radius=15, progress=lambda *a: seen.append(a))
    assert seen[-1] == (5, 5)


def test_true_prints_to_sys_stderr(capsys):
    aggsim.dlca(size=64, fill=0.05, progress=True)
    err = capsys.readouterr().err
    assert "dlca:" in err and "merges" in err and err.endswith("\n")


def test_off_by_default(capsys):
    aggsim.dla(particles=500)
    assert capsys.readouterr().err == ""
