"""The referee: one hand-made failing case per kind of violation, and agreement with brute force."""

from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.grid import Grid
from mrmp.sim.referee import check_paths

GRID = Grid.from_rows(["....", ".@..", "....", "...."])  # blocked cell (2, 1)


def kinds(paths):
    return sorted((c.kind, c.tick, c.robots) for c in check_paths(GRID, paths))


def test_valid_plan_has_no_finding():
    assert kinds({"A": [(0, 0), (0, 1), (0, 2)], "B": [(3, 3), (2, 3), (1, 3)]}) == []


def test_following_is_allowed():
    assert kinds({"A": [(0, 0), (0, 1), (0, 2)], "B": [(0, 1), (0, 2), (0, 3)]}) == []


def test_vertex_collision():
    assert kinds({"A": [(0, 0), (0, 1)], "B": [(0, 2), (0, 1)]}) == [("vertex", 1, ("A", "B"))]


def test_swap_collision():
    assert kinds({"A": [(0, 0), (0, 1)], "B": [(0, 1), (0, 0)]}) == [("swap", 1, ("A", "B"))]


def test_obstacle_entry():
    assert kinds({"A": [(1, 1), (2, 1)]}) == [("obstacle", 1, ("A",))]


def test_leaving_the_grid():
    assert kinds({"A": [(0, 0), (-1, 0)]}) == [("off_grid", 1, ("A",))]


def test_jump():
    assert kinds({"A": [(0, 0), (0, 2)]}) == [("jump", 1, ("A",))]


def test_collision_at_start_and_after_a_path_ends():
    assert kinds({"A": [(0, 0)], "B": [(0, 0)]}) == [("vertex", 0, ("A", "B"))]
    assert kinds({"A": [(0, 1)], "B": [(0, 3), (0, 2), (0, 1)]}) == [("vertex", 2, ("A", "B"))]


def brute_force(grid, paths):
    """Independent check: compare every pair of robots at every tick, and every robot against the map."""
    ids = list(paths)
    length = max(len(p) for p in paths.values())
    at = {r: list(paths[r]) + [paths[r][-1]] * (length - len(paths[r])) for r in ids}
    found = set()
    for t in range(length):
        for r in ids:
            x, y = at[r][t]
            if not (0 <= x < grid.x_size and 0 <= y < grid.y_size):
                found.add(("off_grid", t, (r,)))
            elif grid.is_blocked((x, y)):
                found.add(("obstacle", t, (r,)))
            if t and abs(x - at[r][t - 1][0]) + abs(y - at[r][t - 1][1]) > 1:
                found.add(("jump", t, (r,)))
        for i, r in enumerate(ids):
            for s in ids[i + 1 :]:
                if at[r][t] == at[s][t]:
                    found.add(("vertex-pair", t, (r, s)))
                if t and at[r][t] == at[s][t - 1] and at[s][t] == at[r][t - 1] and at[r][t] != at[r][t - 1]:
                    found.add(("swap", t, (r, s)))
    return found


def normalise(collisions):
    out = set()
    for c in collisions:
        if c.kind == "vertex":
            robots = c.robots
            out.update(("vertex-pair", c.tick, (a, b)) for i, a in enumerate(robots) for b in robots[i + 1 :])
        else:
            out.add((c.kind, c.tick, c.robots))
    return out


steps = st.sampled_from([(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1), (0, 2)])


@st.composite
def random_plans(draw):
    robots = draw(st.integers(1, 4))
    plans = {}
    for index in range(robots):
        x, y = draw(st.integers(-1, 4)), draw(st.integers(-1, 4))
        path = [(x, y)]
        for move in draw(st.lists(steps, max_size=6)):
            x, y = x + move[0], y + move[1]
            path.append((x, y))
        plans[f"r{index}"] = path
    return plans


@settings(max_examples=400, derandomize=True)
@given(random_plans())
def test_referee_agrees_with_brute_force(plans):
    assert normalise(check_paths(GRID, plans)) == brute_force(GRID, plans)
