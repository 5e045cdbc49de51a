"""Every model a user writes (a file, a request body) names an unknown key with the nearest
valid one, and a value that is not one of the choices with the nearest choice."""

import pytest
from pydantic import ValidationError

from app.server.models import JobOptions, JobRequest, PlanRequest, SimulationRequest
from app.simulation import SimOptions
from app.study.spec import StudyFile
from planner import PlanOptions, Scenario
from planner.validation import KnownKeys, describe, suggest

BODIES = {PlanOptions: {}, JobOptions: {}, SimOptions: {},
          PlanRequest: {"scenario_id": "x"}, SimulationRequest: {"scenario_id": "x"},
          JobRequest: {"scenarios": ["x"]}, StudyFile: {"name": "s", "scenarios": ["x"]},
          Scenario: {"name": "s", "start": [0, 0, 0], "goal": [1, 1, 0]}}


@pytest.mark.parametrize("model", list(BODIES), ids=lambda m: m.__name__)
def test_every_model_names_an_unknown_key_and_the_nearest(model):
    assert issubclass(model, KnownKeys)
    key = sorted(model.model_fields)[0]
    typo = key[:-1] + "q" if len(key) > 3 else key + "q"
    with pytest.raises(ValidationError) as refused:
        model.model_validate({**BODIES[model], typo: 1})
    assert describe(refused.value) == f"unknown key '{typo}' (did you mean '{key}'?)"


@pytest.mark.parametrize("model, body, words", [
    (PlanOptions, {"planner": "rrt_turbo"}, "planner: 'rrt_turbo' is not a planner (did you "
                                            "mean 'rrt'?)"),
    (PlanOptions, {"metric": "l2"}, "metric: 'l2' is not a metric (use one of steering, se2)"),
    (SimOptions, {"controller": "pid"}, "controller: 'pid' is not a controller"),
    (JobRequest, {"scenarios": ["x"], "parameters": [{"steering": "reeds_shepp"}]},
     "parameters[0].steering: 'reeds_shepp' is not a steering (did you mean 'reeds-shepp'?)"),
])
def test_a_wrong_choice_is_named_with_the_nearest(model, body, words):
    with pytest.raises(ValidationError) as refused:
        model.model_validate(body)
    assert describe(refused.value).startswith(words)


def test_suggest_prefers_the_choice_a_key_is_made_of():
    assert suggest("rrt_turbo", ["rrt", "rrtstar"]) == " (did you mean 'rrt'?)"
    assert suggest("zzz", ["a", "b"]) == " (use one of a, b)"
