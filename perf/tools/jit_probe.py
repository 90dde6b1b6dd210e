#!/usr/bin/env python3
"""Where lavapipe spends a pass's time, read from its JIT code.

Runs `mrgi bench` on one technique level (or attaches to a running mrgi process), samples it
with `perf record`, copies the process's anonymous executable memory (llvmpipe's JIT code) out of
/proc/PID/mem while it still runs, disassembles it with objdump and prints, per hot code region,
its hottest loops: instructions per iteration, stack references (spills), scalar lane loads
(vmovd / vpinsrd with an index register: what a per-lane gather compiles to) and divisions.

Lavapipe's code has no symbols, so a region is not named by pass; compare regions between two
builds by their loops' sizes, or change one shader and see which region moves. Findings that came
from it (frame_constants.glsl MRGI_UNIFORM_COPIES, upload_gather.glsl, tsdf_volume.glsl): uniform
reads after any branch are per-lane gathers; storage-buffer loads at per-lane addresses are a
loop with a branch per lane; texel buffers and images load with vector inserts.

Needs root (or ptrace rights) for /proc/PID/mem and perf, plus objdump (binutils).

  perf/tools/jit_probe.py -o /tmp/probe -- --techniques ssrt --levels fast --scenes desk_spot
  perf/tools/jit_probe.py --pid 1234 -o /tmp/probe
"""
import argparse
import collections
import os
import re
import shutil
import signal
import subprocess
import sys
import time


def fail(msg):
    print(f"jit_probe: {msg}", file=sys.stderr)
    sys.exit(1)


def dump_code(pid, out):
    """Copies every anonymous executable mapping of `pid` into out/<start>.bin."""
    regions = []
    with open(f"/proc/{pid}/maps") as maps, open(f"/proc/{pid}/mem", "rb", 0) as mem:
        for line in maps:
            parts = line.split()
            if "x" not in parts[1] or (len(parts) > 5 and parts[5].strip()):
                continue
            start, end = (int(x, 16) for x in parts[0].split("-"))
            if end - start > (64 << 20):
                continue
            try:
                mem.seek(start)
                data = mem.read(end - start)
            except OSError:
                continue
            path = os.path.join(out, f"{start:x}.bin")
            with open(path, "wb") as f:
                f.write(data)
            regions.append((start, len(data), path))
    return regions


def sample_ips(perf_data):
    text = subprocess.run(["perf", "script", "-i", perf_data, "-F", "ip"], capture_output=True,
                          text=True, check=False).stdout
    counts = collections.Counter()
    for line in text.split():
        try:
            counts[int(line, 16)] += 1
        except ValueError:
            pass
    return counts


def disassemble(start, path):
    asm = subprocess.run(["objdump", "-D", "-b", "binary", "-m", "i386:x86-64",
                          f"--adjust-vma={start:#x}", path], capture_output=True, text=True,
                         check=True).stdout
    out = []
    for line in asm.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\t(?:[0-9a-f]{2} )+\s*\t(.*)", line)
        if m:
            out.append((int(m.group(1), 16), m.group(2).strip()))
    return out


LANE_LOAD = re.compile(r"(vmovd|vpinsrd)\s+(\$0x\d,)?\(%r\w+,%r\w+,4\)")


def report(regions, counts, out, top):
    total = sum(counts.values()) or 1
    per_region = []
    for start, size, path in regions:
        c = sum(v for a, v in counts.items() if start <= a < start + size)
        per_region.append((c, start, size, path))
    per_region.sort(reverse=True)
    print(f"{total} samples; JIT regions by share:")
    for c, start, size, path in per_region[:top]:
        if c < 0.005 * total:
            break
        print(f"region {start:x} ({size} bytes): {100.0 * c / total:.1f} % of samples")
        ins = disassemble(start, path)
        with open(os.path.join(out, f"{start:x}.asm"), "w") as f:
            f.write("\n".join(f"{counts.get(a, 0):6d} {a:x} {t}" for a, t in ins))
        loops = []
        for a, t in ins:
            m = re.match(r"j\w+\s+0x([0-9a-f]+)", t)
            if not m:
                continue
            target = int(m.group(1), 16)
            if target < a and a - target > 1000:
                body = [(x, y) for x, y in ins if target <= x <= a]
                loops.append((sum(counts.get(x, 0) for x, _ in body), target, a, body))
        loops.sort(reverse=True)
        for c2, target, a, body in loops[:3]:
            ops = collections.Counter(y.split()[0] for _, y in body)
            print(f"  loop {target - start:#x}-{a - start:#x}: {len(body)} instructions, "
                  f"{100.0 * c2 / total:.1f} % of samples, stack refs "
                  f"{sum(1 for _, y in body if '(%rsp)' in y or 'rsp)' in y)}, lane loads "
                  f"{sum(1 for _, y in body if LANE_LOAD.match(y))}, divisions "
                  f"{ops['vdivps'] + ops['vdivss']}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("-o", "--out", required=True, help="folder for the dumps (created; emptied)")
    ap.add_argument("--pid", type=int, help="attach to this running process instead of a bench")
    ap.add_argument("--mrgi", default="build/bin/mrgi", help="mrgi binary (default %(default)s)")
    ap.add_argument("--wait", type=float, default=15.0,
                    help="seconds before sampling, past start-up and shader compilation")
    ap.add_argument("--seconds", type=float, default=5.0, help="sampling time")
    ap.add_argument("--top", type=int, default=8, help="regions shown")
    ap.add_argument("bench_args", nargs="*", help="after --: mrgi bench options")
    args = ap.parse_args()
    for tool in ("perf", "objdump"):
        if not shutil.which(tool):
            fail(f"'{tool}' not found (Debian: linux-perf, binutils)")
    if os.path.exists(args.out):
        shutil.rmtree(args.out)
    os.makedirs(args.out)
    proc = None
    pid = args.pid
    if pid is None:
        if not os.path.exists(args.mrgi):
            fail(f"{args.mrgi} not found (build it, or pass --mrgi)")
        env = dict(os.environ, LP_NUM_THREADS=os.environ.get("LP_NUM_THREADS", "2"))
        cmd = [args.mrgi, "bench", "--frames", "400", "--warmup", "2", "--profile-frames", "0",
               "-q", "-o", os.path.join(args.out, "bench")] + args.bench_args
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        pid = proc.pid
        print(f"jit_probe: {' '.join(cmd)} (pid {pid}); sampling in {args.wait:.0f} s",
              file=sys.stderr)
        time.sleep(args.wait)
        if proc.poll() is not None:
            fail(f"the bench ended early (exit {proc.returncode}); run it alone to see why")
    try:
        perf_data = os.path.join(args.out, "perf.data")
        subprocess.run(["perf", "record", "-F", "4000", "-p", str(pid), "-o", perf_data, "--",
                        "sleep", str(args.seconds)], stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=True)
        regions = dump_code(pid, args.out)
    finally:
        if proc is not None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
    if not regions:
        fail(f"no anonymous executable memory in process {pid}")
    report(regions, sample_ips(perf_data), args.out, args.top)


if __name__ == "__main__":
    main()
