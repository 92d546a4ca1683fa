"""The shop workflow through the Python client that openapi-python-client generates from kerf's
OpenAPI document (clients/generate writes it to clients/python/generated): a tool table and a
machine, deburr as JSON and G-code, segment, contour, engagement, predict, then a job file
submitted as a form, followed until done, its one program and its outputs.zip. Every call goes
through the generated client; a call that returns anything but the documented success fails.

    python3 clients/python/workflow.py http://127.0.0.1:8080
"""

import io
import pathlib
import sys
import time
import zipfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent / "generated"))

from kerf_client import Client  # noqa: E402
from kerf_client.api.contour import contour  # noqa: E402
from kerf_client.api.deburr import deburr, deburr_program  # noqa: E402
from kerf_client.api.engagement import engagement  # noqa: E402
from kerf_client.api.jobs import get_job, get_job_outputs, get_job_program, submit_job  # noqa: E402
from kerf_client.api.machines import put_machine  # noqa: E402
from kerf_client.api.predict import predict, predict_program  # noqa: E402
from kerf_client.api.segment import segment  # noqa: E402
from kerf_client.api.tools import list_tools, put_tool  # noqa: E402
from kerf_client.models import (  # noqa: E402
    ContourAnswer,
    ContourRequest,
    DeburrAnswer,
    DeburrRequest,
    Dialect,
    EngagementAnswer,
    EngagementRequest,
    JobForm,
    JobResultContour,
    JobResultDeburr,
    JobResultSegment,
    JobStatus,
    JobView,
    MachineProfile,
    PredictAnswer,
    PredictRequest,
    SegmentAnswer,
    SegmentRequest,
    Submitted,
    Tool,
    ToolKind,
)
from kerf_client.types import File  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def expect(answer, kind):
    """The answer, which must be of the documented success type (a Problem is a failure)."""
    if not isinstance(answer, kind):
        raise SystemExit(f"expected {kind.__name__}, got {answer!r}")
    return answer


def main(base_url: str) -> None:
    client = Client(base_url=base_url, raise_on_unexpected_status=True, timeout=120)

    ball = Tool(kind=ToolKind.BALL, radius=3, flutes=2, name="R3 ball")
    expect(put_tool.sync(7, client=client, body=ball), Tool)
    finishing = Tool.from_dict({
        "kind": "ball", "radius": 3, "flutes": 2, "helix_deg": 30,
        "shape_error": [{"angle_deg": 0, "error": 0.004}, {"angle_deg": 90, "error": 0.009}],
        "stiffness": {"kind": "modal",
                      "x": [{"stiffness": 3000, "frequency_hz": 1800, "damping_ratio": 0.04}],
                      "y": [{"stiffness": 3000, "frequency_hz": 1800, "damping_ratio": 0.04}]},
    })
    expect(put_tool.sync(3, client=client, body=finishing), Tool)
    numbers = [tool.number for tool in expect(list_tools.sync(client=client), list)]
    assert 3 in numbers and 7 in numbers, numbers
    vmc = MachineProfile(name="vmc", block_time_ms=2, max_feed=10000, rapid_feed=24000)
    expect(put_machine.sync("vmc", client=client, body=vmc), MachineProfile)

    hole = DeburrRequest.from_dict({
        "tool": 7, "machine": "vmc", "edge": "outer", "cut_amount": 0.3, "feed": 400,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 6},
    })
    answer = expect(deburr.sync(client=client, body=hole), DeburrAnswer)
    assert answer.tool.number == 7 and len(answer.points) > 100, answer.summary
    program = expect(deburr_program.sync(client=client, body=hole, dialect=Dialect.LINUXCNC), str)
    assert "(KERF DEBURR)" in program and "M30" in program, program[:200]

    circle = SegmentRequest.from_dict({
        "tool": 7, "machine": "vmc", "feed": 1200,
        "curve": {"kind": "circle", "centre": [30, 20, -2], "radius": 20},
    })
    segmented = expect(segment.sync(client=client, body=circle), SegmentAnswer)
    assert segmented.chord_error > 0

    outline = ContourRequest.from_dict({
        "tool": 7, "machine": "vmc", "contour": [[0, 0], [60, 0], [60, 40], [0, 40]],
        "side": "outside", "depths": {"top": 0, "bottom": -4, "step": 2}, "feed": 800, "spindle_rpm": 8000,
    })
    contoured = expect(contour.sync(client=client, body=outline), ContourAnswer)
    assert len(contoured.layers) == 2, [layer.z for layer in contoured.layers]

    pocket = EngagementRequest.from_dict({
        "tool": 7, "spindle_rpm": 8000, "feed_per_tooth": 0.04, "flute_counts": [2, 4],
        "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
        "path": [[25, 25], [75, 25], [75, 31], [25, 31]],
    })
    engaged = expect(engagement.sync(client=client, body=pocket), EngagementAnswer)
    assert engaged.samples and engaged.tool.number == 7

    dome = PredictRequest.from_dict({
        "tool": 3, "feed": 1600, "spindle_rpm": 8000, "cutting": {"ktc": 2000, "krc": 800, "kac": 300},
        "path": {"kind": "points", "points": [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]},
        "stock": {"kind": "plane", "point": [0, 0, 0.1], "normal": [0, 0, 1], "min": [-5, -5], "max": [8, 5]},
    })
    predicted = expect(predict.sync(client=client, body=dome), PredictAnswer)
    assert predicted.passes, predicted.summary
    corrected = expect(predict_program.sync(client=client, body=dome), str)
    assert "KERF CORRECTED PATH" in corrected, corrected[:200]

    shop = (ROOT / "examples" / "shop-job.toml").read_bytes()
    form = JobForm(file=File(payload=io.BytesIO(shop), file_name="shop-job.toml", mime_type="application/toml"))
    submitted = expect(submit_job.sync(client=client, body=form), Submitted)
    job = expect(get_job.sync(submitted.id, client=client), JobView)
    deadline = time.monotonic() + 120
    while job.status in (JobStatus.QUEUED, JobStatus.RUNNING) and time.monotonic() < deadline:
        time.sleep(0.2)
        job = expect(get_job.sync(submitted.id, client=client), JobView)
    assert job.status == JobStatus.DONE, job
    kinds = [type(result) for result in job.results]
    assert kinds == [JobResultDeburr, JobResultContour, JobResultSegment], kinds
    assert isinstance(job.results[0].result, DeburrAnswer) and job.results[0].result.points
    whole = expect(get_job_program.sync(submitted.id, client=client), str)
    assert "O4711" in whole, whole[:200]
    archive = zipfile.ZipFile(expect(get_job_outputs.sync(submitted.id, client=client), File).payload)
    names = archive.namelist()
    assert "program.nc" in names and "job.json" in names, names
    print(f"python workflow: {len(program)} B deburr program, job {submitted.id} with {len(names)} files")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "http://127.0.0.1:8080")
