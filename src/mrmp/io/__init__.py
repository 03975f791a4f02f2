"""File formats: the only layer of mrmp that reads or writes files.

* :mod:`mrmp.io.movingai` -- MovingAI ``.map`` grids and ``.scen`` agent lists;
* :mod:`mrmp.io.scenario_file` -- the strict YAML scenario format;
* :mod:`mrmp.io.validate` -- check any of those files and list its problems;
* :mod:`mrmp.io.results` -- run results as JSON (written atomically) and back.

Every bad input raises :class:`~mrmp.core.errors.InputError` whose problems
name ``file:line`` and what is wrong there; nothing leaks a traceback.

Examples
--------
>>> scenario = scenario_from_text("map: {rows: ['..']}\\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\\n", "x.yaml")
>>> scenario.robots[0].goal, scenario.grid.y_size
((0, 1), 2)
"""

from mrmp.io.movingai import (
    ScenEntry,
    map_to_text,
    parse_map,
    parse_scen,
    read_map,
    read_scen,
    read_scen_entries,
    scen_to_text,
    shortest_path_length,
    write_map,
    write_scen,
)
from mrmp.io.results import (
    grid_from_result_dict,
    read_result_json,
    result_from_dict,
    result_to_dict,
    result_to_json,
    write_result_json,
)
from mrmp.io.scenario_file import (
    load_movingai_scenario,
    load_scenario,
    save_scenario,
    scenario_from_text,
    scenario_to_yaml,
)
from mrmp.io.validate import validate_file

__all__ = [
    "ScenEntry",
    "grid_from_result_dict",
    "load_movingai_scenario",
    "load_scenario",
    "map_to_text",
    "parse_map",
    "parse_scen",
    "read_map",
    "read_result_json",
    "read_scen",
    "read_scen_entries",
    "result_from_dict",
    "result_to_dict",
    "result_to_json",
    "save_scenario",
    "scen_to_text",
    "scenario_from_text",
    "scenario_to_yaml",
    "shortest_path_length",
    "validate_file",
    "write_map",
    "write_result_json",
    "write_scen",
]
