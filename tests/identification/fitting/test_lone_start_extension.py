"""The search's last resort before a warning: a lone best start gets company (fitting.search._extend_if_alone).

The problem is a one-coordinate double well, solved by the search's own least-squares task:
residuals (theta^2 - 1, sqrt(1 + (1 + theta)/8)) have local minima near theta = -1 (misfit 1)
and theta = +1 (misfit about 1.25), so which basin a start ends in is known in advance."""
from dataclasses import dataclass

import numpy as np

from identification.fitting.engine import SerialEngine
from identification.fitting.ensemble import misfit_threshold
from identification.fitting.result import MIN_AGREEING
from identification.fitting.search import _extend_if_alone
from identification.fitting.multistart import StartRecord

RESIDUALS, COORDINATES = 100, 1      # the n and d the threshold is computed for


@dataclass(frozen=True)
class _Box:
    def bounds(self):
        return np.array([[-2.0, 2.0]])


@dataclass(frozen=True)
class DoubleWell:
    space: _Box = _Box()

    def residuals(self, theta):
        theta = np.atleast_2d(theta)[:, 0]
        return np.column_stack([theta ** 2 - 1.0, np.sqrt(1.0 + (1.0 + theta) / 8.0)])

    def misfit(self, theta):
        return np.sum(self.residuals(theta) ** 2, axis=1)


class _Bars:
    def stage(self, index, count, again=False, more=False, total=None):
        pass


def records(final_thetas, waiting_thetas, waiting_stage=0):
    """Records of the last stage (1) at ``final_thetas``, and of ``waiting_stage`` at ``waiting_thetas``."""
    problem = DoubleWell()
    out = [StartRecord(i, np.array([t]), float(problem.misfit([[t]])[0]), 1, 1)
           for i, t in enumerate(final_thetas)]
    out += [StartRecord(len(final_thetas) + i, np.array([t]), float(problem.misfit([[t]])[0]), waiting_stage, 1)
            for i, t in enumerate(waiting_thetas)]
    return out


def extend(found, starts=3):
    return _extend_if_alone(DoubleWell(), SerialEngine(), found, (starts, 50), 1, (RESIDUALS, COORDINATES), _Bars())


def agreeing(found):
    final = [r for r in found if r.stage == 1]
    best = min(r.misfit for r in final)
    return sum(r.misfit <= best + misfit_threshold(best, RESIDUALS, COORDINATES) for r in final)


def test_a_lone_best_start_makes_the_next_starts_run_the_last_stage():
    # one final start in the deep well, two in the shallow one; of the waiting starts two lie in the deep well
    found = records([-1.0, 1.0, 1.0], [-0.6, -1.4, 0.7])
    assert agreeing(found) == 1
    found, added, agreed_before = extend(found)
    assert added == 3 and agreed_before == 1 and all(r.stage == 1 for r in found)
    assert agreeing(found) == 3 >= MIN_AGREEING
    ends = sorted(float(r.theta[0]) for r in found if r.start >= 3)
    assert ends[0] < -0.9 and ends[1] < -0.9 and ends[2] > 0.9     # each went to its own well's bottom
    assert [r.misfit for r in found] == sorted(r.misfit for r in found)


def test_starts_that_already_agree_are_left_alone():
    found = records([-1.0, -1.0, 1.0], [-0.6])
    before = [(r.start, r.stage, r.misfit) for r in found]
    found, added, agreed_before = extend(found)
    assert added == 0 and agreed_before == 2 and [(r.start, r.stage, r.misfit) for r in found] == before


def test_only_the_best_waiting_starts_run_and_the_rest_wait():
    # five waiting starts, room for three: the three lowest misfits run (-0.7, -1.3, 0.9), 1.6 and -1.9 wait
    found = records([-1.0, 1.0, 1.0], [1.6, -0.7, -1.9, -1.3, 0.9])
    misfit = {r.start: r.misfit for r in found}
    expected = sorted(range(3, 8), key=lambda start: misfit[start])[:3]
    assert sorted(expected) == [4, 6, 7]
    found, added, _ = extend(found)
    ran = sorted(r.start for r in found if r.start >= 3 and r.stage == 1)
    assert added == 3 and ran == [4, 6, 7]
    for r in found:
        if r.start in (3, 5):
            assert r.stage == 0 and r.evaluations == 1 and r.history == []
        elif r.start in ran:
            assert r.evaluations > 1 and len(r.history) == 1


def test_with_no_start_left_in_the_stage_before_the_earlier_ones_run():
    # a reduced budget keeps the same few starts to the end: the stage before the last has none
    # waiting, so the starts that stopped two stages back run
    found = records([-1.0, 1.0, 1.0], [-0.6, 0.8], waiting_stage=-1)
    found, added, _ = extend(found)
    assert added == 2 and agreeing(found) == 2


def test_with_no_other_start_at_all_nothing_runs():
    found = records([-1.0], [])
    found, added, agreed_before = extend(found)
    assert added == 0 and agreed_before == 1 and len(found) == 1
