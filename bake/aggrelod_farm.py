#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""aggrelod-farm: a tiled bake on a Dask cluster (docs/command-line.md, "aggrelod-farm").

    aggrelod-farm SCENE -o OUTDIR [--scheduler tcp://HOST:PORT | --workers N]
                  [--aggrelod PATH] [--tile-size S|auto] [--tile-cache DIR] [any bake option]

The pieces of the tiled bake (`aggrelod bake --tile-task plan` lists them) run as Dask tasks,
each one `aggrelod bake --tile-task PIECE[,PIECE...]` process on a worker (a batch of a wave's
pieces, so that the scene is read and laid out once per batch), in waves: the cells' graphs
(automatic thresholds only), the cells, then the parent cells quadtree level by quadtree level,
then the proxies of the whole hierarchy in two phases of shares, and last the whole bake, which
finds every piece and every proxy in the cache and writes the outputs. Pieces go
through the tile cache (a folder every worker sees: shared storage on several machines), so a
task that is retried after its worker died redoes only its own piece, and the result is
byte-identical to `aggrelod bake --tile-size S` on one machine. Without --scheduler, a
LocalCluster of N worker processes (default: one per core) on the loopback interface.
Needs Debian's python3-distributed.
"""
import argparse
import ctypes
import json
import os
import signal
import subprocess
import sys
import time

RETRIES = 3  # a task whose worker died is run again (Dask counts it); beyond, the bake fails
# Input triangles per proxies share: a share holds the whole scene, the hierarchy without its
# meshes, and the originals and exact aggregates of its part of the world (the 65,536-object
# world's six shares of 1.3 million triangles each peak at 1.2-1.6 GiB).
SHARE_TRIANGLES = 1_500_000


def proxy_share_count(plan, slots, asked=0):
    """Shares of the proxies: `asked` when given, else a multiple of the worker threads with at
    most SHARE_TRIANGLES input triangles each. The result does not depend on it."""
    if asked > 0:
        return asked
    triangles = int(plan.get("triangles", 0))
    rounds = max(1, -(-triangles // (slots * SHARE_TRIANGLES)))
    return slots * rounds


def _die_with_parent():
    """In the child: be killed when the worker that started it dies (Linux prctl)."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def run_piece(command):
    """One aggrelod process (on a worker); raises with its messages when it fails."""
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          preexec_fn=_die_with_parent)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} exited with {done.returncode}: {done.stderr.strip()}")
    return done.stdout


def piece_commands(plan, proxy_shares):
    """The waves of pieces, each a list of --tile-task values, in the order they must run:
    the hierarchy's pieces, then the proxies' two phases, each cut into proxy_shares shares."""
    waves = []
    if plan["graphs"]:
        waves.append([f"graph:{c}" for c in plan["cells"]])
    waves.append([f"cell:{c}" for c in plan["cells"]])
    for level in sorted({j for j, _, _ in plan["parents"]}):
        waves.append([f"parent:{j}:{r}:{c}" for j, r, c in plan["parents"] if j == level])
    for phase in (1, 2):
        waves.append([f"proxies:{phase}:{k}:{proxy_shares}" for k in range(proxy_shares)])
    return waves


def batches(wave, count):
    """A wave's pieces as at most `count` comma-separated --tile-task lists, dealt in turn: each
    aggrelod process reads the whole scene once for its batch, not once per piece (proxies
    shares stay one per process)."""
    if wave[0].startswith("proxies:") or len(wave) <= count:
        return wave
    return [",".join(wave[k::count]) for k in range(count)]


def bake_on(client, aggrelod, scene, outdir, tile_size, cache, bake_options, threads="0", log=print, proxy_shares=0):
    """The whole farm bake on a connected dask.distributed Client; returns the final bake's output.
    bake_options: further `aggrelod bake` options (not --threads, --tile-*); proxy_shares: see
    proxy_share_count."""
    if __name__ != "__main__":  # workers on other machines need not have this file: ship it with the tasks
        try:
            import cloudpickle
            cloudpickle.register_pickle_by_value(sys.modules[__name__])
        except (ImportError, AttributeError, ValueError):
            pass
    base = [aggrelod, "bake", scene, "-o", outdir, "--tile-size", tile_size] + bake_options
    plan = json.loads(run_piece(base + ["--tile-task", "plan", "--quiet"]))
    if plan["tiled"]:
        # Shares of the proxies: a part of the world of about equal estimated work each, as many
        # as keep each share's memory bounded, at least one per worker thread.
        slots = max(1, sum(client.nthreads().values()))
        for wave in piece_commands(plan, proxy_share_count(plan, slots, proxy_shares)):
            started = time.monotonic()
            commands = [base + ["--tile-cache", cache, "--tile-task", task, "--quiet", "--threads", "1"]
                        for task in batches(wave, 4 * slots)]
            futures = client.map(run_piece, commands, retries=RETRIES, pure=False)
            client.gather(futures)
            log(f"aggrelod-farm: {len(wave)} {wave[0].split(':')[0]} pieces in {time.monotonic() - started:.1f} s")
    final = base + ["--threads", threads] + (["--tile-cache", cache] if plan["tiled"] else [])
    return client.submit(run_piece, final, retries=RETRIES, pure=False).result()


def main(argv=None):
    parser = argparse.ArgumentParser(prog="aggrelod-farm", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("-o", "--output", required=True, help="output folder (shared by every worker)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://10.0.0.1:8786")
    where.add_argument("--workers", type=int, default=0,
                       help="worker processes of the local cluster (default: one per core)")
    parser.add_argument("--aggrelod", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "aggrelod"),
                        help="the aggrelod executable the workers run (default: beside this script)")
    parser.add_argument("--tile-size", default="auto", help="tile side in scene units, or auto (default)")
    parser.add_argument("--tile-cache", help="folder of the pieces (default: OUTDIR.tile-cache)")
    parser.add_argument("--threads", default="0", help="threads of the final bake (pieces run on one each)")
    parser.add_argument("--proxy-shares", type=int, default=0,
                        help="shares of the proxies' work (default: one per worker thread, more for a world "
                             f"over {SHARE_TRIANGLES:,} triangles per worker thread, to bound each one's memory)")
    args, bake_options = parser.parse_known_args(argv)
    for option in ("--tile-task",):
        if option in bake_options:
            parser.error(f"{option} is the farm's to choose")
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        sys.exit("aggrelod-farm: needs dask.distributed (Debian package python3-distributed)")
    scene = os.path.abspath(args.scene)
    outdir = os.path.abspath(args.output)
    cache = os.path.abspath(args.tile_cache or outdir.rstrip("/") + ".tile-cache")
    aggrelod = os.path.abspath(args.aggrelod)
    if not os.access(aggrelod, os.X_OK):
        sys.exit(f"aggrelod-farm: {aggrelod} is not an executable (give --aggrelod PATH)")
    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=args.workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None)
        client = Client(cluster)
    try:
        sys.stdout.write(bake_on(client, aggrelod, scene, outdir, args.tile_size, cache, bake_options, args.threads,
                                 log=lambda line: print(line, file=sys.stderr), proxy_shares=args.proxy_shares))
    except Exception as error:  # the failing piece's own message
        sys.exit(f"aggrelod-farm: {error}")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


if __name__ == "__main__":
    main()
