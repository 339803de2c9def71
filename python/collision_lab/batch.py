"""collision_lab.sweep for batch systems (docs/python.md): `python3 -m collision_lab.batch`,
installed as the program collision_lab_sweep too.

  python3 -m collision_lab.batch SWEEP.yaml -o OUT.jsonl [--shard I/N] [--workers W]
  python3 -m collision_lab.batch SWEEP.yaml --merge SHARD.jsonl... -o ALL.csv|ALL.jsonl

SWEEP.yaml (or .json) holds `scenes:` (a list of scene dicts) or `grid:` (parameter ->
list of values) with `base:` (a scene dict in which a string "$name" stands for the grid
point's value of parameter name), and optional `options:` (run() options for every scene).
--shard I/N runs the I-th (0 <= I < N) of N contiguous chunks of the scene list and writes
one JSON line per scene: {"scene": its index in the sweep, the parameters, the summary
columns of collision_lab.sweep}. --merge checks that the shard files hold every scene once
and writes them in the sweep's order: the JSON lines, or the CSV of collision_lab.sweep's
table (index column "scene"). The merged table equals the unsharded one, value for value,
except compute_time_s (each run's wall time).
"""
import argparse
import json

import yaml

from ._sweep import run_chunk, scene_job, scene_list, sweep_table


def substitute(template, point):
    """`template` with every string "$name" replaced by point[name]."""
    if isinstance(template, dict):
        return {key: substitute(value, point) for key, value in template.items()}
    if isinstance(template, list):
        return [substitute(value, point) for value in template]
    if isinstance(template, str) and template.startswith('$') and template[1:] in point:
        return point[template[1:]]
    return template


def load_sweep(path):
    """(parameter names, [(parameters, scene dict)], options) of a sweep description."""
    with open(path) as f:
        description = yaml.safe_load(f)
    grid = description.get('grid')
    base = description.get('base', {})
    parameters, scenes = scene_list(description.get('scenes'), grid,
                                    (lambda point: substitute(base, point)) if grid is not None else None)
    names = [name for name, _ in parameters]
    points = [dict(zip(names, values)) for values in zip(*(values for _, values in parameters))] \
        if parameters else [{} for _ in scenes]
    return names, list(zip(points, scenes)), dict(description.get('options') or {})


def shard_range(text, count):
    """[begin, end) of shard 'I/N' of `count` scenes: contiguous, sizes differing by <= 1."""
    try:
        index, shards = (int(part) for part in text.split('/'))
    except ValueError:
        raise SystemExit('collision_lab.batch: --shard %r is not I/N' % text)
    if not 0 <= index < shards:
        raise SystemExit('collision_lab.batch: --shard %s: I must be in [0, N)' % text)
    return index * count // shards, (index + 1) * count // shards


def run_shard(args):
    _, scenes, options = load_sweep(args.sweep)
    options.setdefault('events', 'none')
    begin, end = shard_range(args.shard, len(scenes)) if args.shard else (0, len(scenes))
    jobs = [scene_job(scene, options) for _, scene in scenes[begin:end]]
    with open(args.output, 'w') as out:
        for number, ((point, _), row) in enumerate(zip(scenes[begin:end], run_chunk(jobs, args.workers)),
                                                   start=begin):
            out.write(json.dumps(dict({'scene': number}, **point, **row)) + '\n')


def merge(args):
    names, scenes, _ = load_sweep(args.sweep)
    rows = {}
    for path in args.shards:
        with open(path) as f:
            for line in f:
                row = json.loads(line)
                if row['scene'] in rows:
                    raise SystemExit('collision_lab.batch: scene %d is in two shard files' % row['scene'])
                rows[row['scene']] = (line, row)
    missing = sorted(set(range(len(scenes))) - set(rows))
    if missing or len(rows) != len(scenes):
        raise SystemExit('collision_lab.batch: %d of %d scenes missing (first: %s); run their shards'
                         % (len(missing), len(scenes), missing[:5]))
    ordered = [rows[number] for number in range(len(scenes))]
    if args.output.endswith('.csv'):
        table = sweep_table([{k: v for k, v in row.items() if k != 'scene'} for _, row in ordered], names)
        table.to_csv(args.output, index_label='scene')
    else:
        with open(args.output, 'w') as out:
            out.writelines(line for line, _ in ordered)


def main():
    parser = argparse.ArgumentParser(prog='collision_lab_sweep', description=__doc__.split('\n\n')[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    parser.add_argument('sweep', help='the sweep description (YAML or JSON)')
    parser.add_argument('-o', '--output', required=True, help='the JSON lines file (merge: .csv or .jsonl)')
    parser.add_argument('--shard', help='I/N: run the I-th of N contiguous chunks (0 <= I < N)')
    parser.add_argument('--workers', type=int, default=1,
                        help='C++ threads (default 1: one core per batch task)')
    parser.add_argument('--merge', nargs='+', dest='shards', metavar='SHARD',
                        help='merge these shard files into the one table')
    args = parser.parse_args()
    if args.shards:
        merge(args)
    else:
        run_shard(args)


if __name__ == '__main__':
    main()
