#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""aggrelod-farm on a local Dask cluster of 2 worker processes (loopback only), against the
tiled bake on one machine of the same generated world:

    test_farm.py identical|killed AGGRELOD MAKE_SAMPLE WORKDIR

identical: the farm's outputs are byte-identical to `aggrelod bake --tile-size 48`.
killed: one worker is killed (SIGKILL) while the cells are being baked; Dask runs its task
again on the restarted worker, and the outputs are still byte-identical.
Exit 0 when the check holds, 1 when it does not, 77 (skipped) without dask.distributed."""
import filecmp
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bake"))
import aggrelod_farm  # noqa: E402

def main():
    mode, aggrelod, make_sample, work = sys.argv[1:5]
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("test_farm: SKIPPED: dask.distributed (python3-distributed) is not installed")
        return 77

    work = os.path.join(os.path.abspath(work), "farm_" + mode)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scene = os.path.join(work, "world.glb")
    subprocess.run([make_sample, "world", "--objects", "300", "--seed", "4", "-o", scene], check=True,
                   stdout=subprocess.DEVNULL)
    options = ["--support", "terrain|road", "--delta", "0.5,1,2,4,8,16"]
    reference = os.path.join(work, "one_machine")
    subprocess.run([aggrelod, "bake", scene, "-o", reference, "--tile-size", "48", "--quiet"] + options, check=True)

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
    client = Client(cluster)
    outdir, cache = os.path.join(work, "farm"), os.path.join(work, "cache")
    killed = []
    try:
        if mode == "killed":
            errors = []

            def bake():
                try:
                    aggrelod_farm.bake_on(client, aggrelod, scene, outdir, "48", cache, options, log=lambda _: None)
                except Exception as error:  # reported below
                    errors.append(error)

            baking = threading.Thread(target=bake)
            baking.start()
            deadline = time.monotonic() + 300
            while baking.is_alive() and time.monotonic() < deadline:
                busy = sorted(address for address, keys in client.processing().items() if keys)
                if busy and os.path.isdir(cache) and any(name.endswith(".piece") for name in os.listdir(cache)):
                    before = client.run(os.getpid)  # worker address -> pid
                    victim = busy[0]  # a worker with a piece in hand
                    os.kill(before[victim], signal.SIGKILL)
                    killed.append(before[victim])
                    break
                time.sleep(0.05)
            baking.join()
            if errors:
                print(f"test_farm: the farm failed after a worker was killed: {errors[0]}")
                return 1
            if not killed:
                print("test_farm: the bake ended before a worker could be killed")
                return 1
            client.wait_for_workers(2, timeout=60)
            after = client.run(os.getpid)
            if killed[0] in after.values():
                print("test_farm: the killed worker is still there")
                return 1
            print(f"test_farm: killed worker pid {killed[0]} mid-bake; workers now {sorted(after.values())}")
        else:
            aggrelod_farm.bake_on(client, aggrelod, scene, outdir, "48", cache, options, log=print)
    finally:
        client.close()
        cluster.close()

    pieces = [name for name in os.listdir(cache) if name.endswith(".piece")]
    different = [name for name in ("levels.glb", "proxies.glb", "scene.aglod")
                 if not filecmp.cmp(os.path.join(reference, name), os.path.join(outdir, name), shallow=False)]
    print(f"test_farm: {len(pieces)} pieces in the cache; outputs differing from the one-machine bake: {different or 'none'}")
    return 1 if different or not pieces else 0


if __name__ == "__main__":  # the workers import this file again (multiprocessing spawn)
    sys.exit(main())
