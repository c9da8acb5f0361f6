"""Reference counting: no growth of the resident set over 10 000 steps driven from Python."""

import numpy as np


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_no_leak_over_10000_steps(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)
    seen = []

    def work(s):
        # What a script does every step: views, copies, a dict, a write.
        v = s.particles.velocity
        v.z[:] = np.minimum(v.z, 0.0)
        seen.append(float(np.sum(s.particles.position.z)))
        s.diagnostics()
        seen.pop()

    for _ in range(1000):  # warm up: allocators and caches reach their size
        sim.step()
        work(sim)
    before = rss_bytes()
    for _ in range(10_000):
        sim.step()
        work(sim)
    sim.run(steps=10_000, callback=work)
    after = rss_bytes()
    print(f"RSS over 20 000 steps (10 000 step() calls, 10 000 run() callbacks): {before / 1e6:.1f} MB -> {after / 1e6:.1f} MB")
    assert after - before < 1 << 20, f"RSS grew by {(after - before) / 1e6:.2f} MB"
