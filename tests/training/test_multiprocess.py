"""Data-parallel training for real: two processes (gloo, CPU) launched by torchrun."""

import json
import os
import subprocess
import sys

import pytest
import yaml

pytest.importorskip("accelerate", reason="needs the train extra (make setup)")


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _train(command: list[str], config: dict, folder,
           **env_extra) -> tuple[list[float], list[float], int]:
    folder.mkdir()
    path = folder / "config.yaml"
    path.write_text(yaml.safe_dump({**config, "out": str(folder / "run")}))
    env = {**os.environ, "OMP_NUM_THREADS": "1", "TOKENIZERS_PARALLELISM": "false",
           **env_extra}
    done = subprocess.run([*command, "train", "--config", str(path)], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    log = (folder / "run" / "train_log.jsonl").read_text().splitlines()
    processes = json.loads((folder / "run" / "run.json").read_text())["processes"]
    steps = [json.loads(line) for line in log]
    return [x["loss"] for x in steps], [x["lr"] for x in steps], processes


@pytest.mark.slow  # trains in two processes and in one
def test_two_processes_train_like_one_with_the_same_global_batch(tiny_gemma_dir, tmp_path):
    """Tests the multi-GPU path on CPUs: two processes (torchrun, gloo) split each batch
    of 4, log one line per step, and their losses equal a single process's on the
    whole batch, step after step."""
    config = {"base_model": tiny_gemma_dir, "seed": 0, "checkpoint_every": 100,
              "precision": "fp32",
              "eval_pairs": 0, "max_steps": 3,
              "lora": {"r": 4, "alpha": 8, "dropout": 0.0},
              "optim": {"lr": 5e-3, "batch_size": 4, "warmup_steps": 0, "epochs": 2},
              "data": {"forms": ["lifted"], "limit": 8, "shots": [0, 2]}}
    single, single_lr, one = _train([sys.executable, "-m", "ara.cli"], config, tmp_path / "one")
    # torchrun starts the two processes (accelerate's own launcher runs one with --cpu);
    # with ACCELERATE_USE_CPU, Accelerator() finds WORLD_SIZE=2 and takes gloo
    launcher = [sys.executable, "-m", "torch.distributed.run", "--nproc_per_node", "2",
                "--master_port", str(_free_port()), "-m", "ara.cli"]
    double, double_lr, two = _train(launcher, config, tmp_path / "two",
                                    ACCELERATE_USE_CPU="true")
    assert (one, two) == (1, 2)
    assert len(single) == len(double) == 3
    # One schedule, whatever the number of processes (accelerate's stepping had run it
    # once per process: lr 0 from the second step here)
    assert double_lr == pytest.approx(single_lr) and single_lr[1] > 0
    assert double == pytest.approx(single, rel=2e-3)
    assert single[-1] < single[0]  # it learns, so later steps test the shared updates
