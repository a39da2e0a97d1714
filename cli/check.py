"""``adhcontact check``: validate a scene and show what a run would be,
without running it: the mesh and contact sizes, the estimate of memory,
time and output (from the mesh built: its counts are those of the mesh
line), the explicit Euler bound of the bonding law, the smallness figures
and the scene's warnings; with ``--resolved``, the resolved scene (every
default filled in) as JSON."""

import json
import sys
from pathlib import Path

import click

from .common import CliError, load_scene, read_scene, scene_folder, time_line


@click.command()
@click.argument("scene", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--resolved", is_flag=True,
              help="Also print the resolved scene (every default filled in) as JSON.")
def check(scene, resolved):
    """Validate SCENE (the built-in default if omitted) and print what a run would be."""
    from adhesive_contact import SceneError, parse_scene
    from adhesive_contact.problem.plausibility import prony_note
    from adhesive_contact.resources import built_counts, estimate, mesh_file_refusal, refusal
    from adhesive_contact.storage import plain

    name, text = read_scene(scene)
    try:   # estimated from the scene alone, before anything is built
        parsed = parse_scene(text, scene_folder(scene))
        reason = mesh_file_refusal(parsed)
        est = None if reason else estimate(parsed)
        reason = reason or refusal(est)
    except SceneError as err:
        raise CliError(str(err), 2) from None
    if reason:   # building it would take what the machine does not have
        click.echo(f"{name}: valid scene ({parsed.title}), too large to build here: {reason}")
        if est is not None:
            click.echo(f"  estimate: {est.describe()}")
        click.echo(f"  time: {time_line(parsed)}")
        click.echo("  not built: the mesh, contact and smallness figures need the problem; "
                   "check a coarser scene (mesh.cells, mesh.refine)")
        return
    parsed, problem = load_scene(text, scene_folder(scene), force=True)
    est = estimate(parsed, counts=built_counts(problem))
    boundary = problem.boundary
    click.echo(f"{name}: valid scene ({parsed.title})")
    click.echo(f"  mesh: {problem.mesh.p.shape[1]} nodes, {problem.mesh.t.shape[1]} cells, "
               f"{problem.ndofs} dofs ({problem.free.size} free); "
               + ("no contact boundary" if boundary is None else
                  f"{boundary.facets.size} contact facets, {boundary.nodes.size} contact "
                  f"nodes, {problem.columns.size} contact unknowns"))
    click.echo(f"  time: {time_line(parsed)}")
    click.echo(f"  estimate: {est.describe()}")
    if getattr(problem.bonding, "rate_independent", False):
        from adhesive_contact.problem.damage_lag import DAMAGE_DROP, GLUE_ENERGY_MARGIN
        click.echo("  damage update of the cohesive law: beta stays in [0, 1] for every k; "
                   "its one-level lag is checked after the run (a warning when a facet "
                   f"loses more than {DAMAGE_DROP:g} of its bond in one level or the glue "
                   f"dissipates more than {1 + GLUE_ENERGY_MARGIN:g} G_c per debonded area, "
                   "and where the quasi-static path jumps)")
    elif problem.bonding is not None:
        bound = problem.bonding.stable_step()
        click.echo(f"  explicit Euler bound of the bonding law: k <= {bound:.4g} "
                   f"(k = {parsed.k:.4g}: {'within' if parsed.k <= bound else 'beyond'}; "
                   f"integrator {parsed.contact.integrator})")
    small = problem.smallness
    if small is not None and small.get("held_by_contact"):
        click.echo(f"  smallness: m_A = {small['m_A']:.4g}; the conditions do not apply: only "
                   f"the contact terms hold the body against "
                   f"{', '.join(small['held_by_contact'])}; step energy "
                   f"{'convex' if small['step_energy_convex'] else 'may be nonconvex'}")
    elif small is not None:
        click.echo(f"  smallness: m_A = {small['m_A']:.4g}; error estimate needs > "
                   f"{small['rhs']:.4g} ({'holds' if small['holds'] else 'does not hold'}); "
                   f"step energy {'convex' if small['step_energy_convex'] else 'may be nonconvex'}"
                   f" (m_c c_e^2 = {small['convexity_rhs']:.4g})")
    note = prony_note(parsed)
    if note:
        click.echo(f"  note: {note}")
    for warning in problem.warnings():
        click.echo(f"  warning: {' '.join(str(warning).split())}")
    if resolved:
        click.echo("  resolved scene:")
        json.dump(plain(parsed.resolved), sys.stdout, indent=1)
        click.echo()
