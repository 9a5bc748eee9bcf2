"""The README's set-up commands are the ones CI runs."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ci_runs_the_readme_test_command_verbatim():
    ci = (ROOT / ".ci" / "run").read_text().strip().splitlines()
    readme = (ROOT / "README.md").read_text()
    command = ci[-1]
    assert "pytest" in command
    assert f"```bash\n{command}\n```" in readme


def test_readme_names_the_main_job_and_existing_figure():
    readme = (ROOT / "README.md").read_text()
    assert "```bash\npip install . && impactsym reproduce --out results\n```" in readme
    assert (ROOT / "docs" / "stick_boundary.png").is_file()


def test_readme_python_examples_run():
    readme = (ROOT / "README.md").read_text()
    blocks = readme.split("```python\n")[1:]
    examples = [block.split("```")[0] for block in blocks]
    runnable = [code for code in examples if "from impactsym_numpy" not in code]
    assert len(runnable) >= 2
    for code in runnable:
        exec(compile(code, "README.md", "exec"), {})
