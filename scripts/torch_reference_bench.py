#!/usr/bin/env python3
# The engine's kernels on the reference configuration (docs/design.md §7) written in plain PyTorch,
# so that `make bench` can quote icef_bench's kernel benchmarks against PyTorch measured in the same
# run on the same cores. Same shapes and sizes as bench/nn_bench.cc, 4096 rays x 32 samples:
#
#   hash grid   L = 16, F = 2, T = 2^19, resolutions 16 .. 1024, trilinear    BM_HashGridForward,
#               forward; forward + backward (table and position gradients)    BM_HashGridForwardBackward
#   MLP 0       deformation 55 -> 64 -> 64 -> 64 -> 3 (linear), no biases       BM_MlpForward/0,
#   MLP 1       density 32 -> 64 -> 16                                          BM_MlpForwardBackward/k
#   MLP 2       colour 32 -> 64 -> 64 -> 3 (sigmoid)
#   forward alone, and forward + backward (weight and input gradients)
#
# "Tuned" as far as eager PyTorch on a CPU goes: the hash grid is vectorised over samples and
# corners per level (the pure-PyTorch fallback of the usual NeRF code bases), the inputs are made
# once, and forward-only passes run without autograd.
#
#   python3 scripts/torch_reference_bench.py [--threads 2] [--steps 8] [--json OUT] [--cpp-results IN]
#
# Prints samples/s per kernel and writes them to OUT (JSON) when asked. Needs Debian's python3-torch
# (`scripts/install-deps.sh --bench` installs it, with OpenBLAS as its BLAS).
import argparse, json, sys, time

try:
    import torch
except ImportError:
    sys.exit("torch_reference_bench: PyTorch is not installed (scripts/install-deps.sh --bench installs python3-torch)")

RAYS, SAMPLES_PER_RAY = 4096, 32
LEVELS, FEATURES, LOG2_T, BASE_RES, FINEST_RES = 16, 2, 19, 16, 1024
PRIME1, PRIME2 = 2654435761, 805459861
# bench/nn_bench.cc's BenchMlpOptions(k): (name, widths, sigmoid output)
MLPS = [("deform_55-64-64-64-3", [55, 64, 64, 64, 3], False),
        ("density_32-64-16", [32, 64, 16], False),
        ("colour_32-64-64-3", [32, 64, 64, 3], True)]


def mlp(widths, sigmoid):
    layers = []
    for i in range(len(widths) - 1):
        layers.append(torch.nn.Linear(widths[i], widths[i + 1], bias=False))
        if i + 2 < len(widths):
            layers.append(torch.nn.ReLU())
    if sigmoid:
        layers.append(torch.nn.Sigmoid())
    return torch.nn.Sequential(*layers)


class HashGrid(torch.nn.Module):
    def __init__(self):
        super().__init__()
        t = 1 << LOG2_T
        b = (FINEST_RES / BASE_RES) ** (1.0 / (LEVELS - 1))
        self.levels, offset = [], 0
        for l in range(LEVELS):
            r = int(round(BASE_RES * b ** l))
            dense = (r + 1) ** 3 <= t
            entries = (r + 1) ** 3 if dense else t
            self.levels.append((r, dense, offset))
            offset += (entries + 7) // 8 * 8
        self.table = torch.nn.Parameter(torch.empty(offset, FEATURES).uniform_(-1e-4, 1e-4))
        self.mask = t - 1
        corners = torch.tensor([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=torch.int64)
        self.register_buffer("corners", corners)

    def forward(self, p):
        p = p.clamp(0.0, 1.0)
        feats = []
        for r, dense, offset in self.levels:
            x = p * r
            cell = x.detach().floor().long().clamp(max=r - 1)
            frac = x - cell
            v = cell[:, None, :] + self.corners[None]  # [n, 8, 3]
            if dense:
                idx = v[..., 0] + v[..., 1] * (r + 1) + v[..., 2] * (r + 1) ** 2
            else:
                idx = (v[..., 0] ^ (v[..., 1] * PRIME1) ^ (v[..., 2] * PRIME2)) & self.mask
            w = torch.where(self.corners[None].bool(), frac[:, None, :], 1.0 - frac[:, None, :]).prod(-1)
            vals = self.table[idx + offset]  # [n, 8, F]
            feats.append((w[..., None] * vals).sum(1))
        return torch.cat(feats, dim=-1)


def make_positions(gen):
    """Samples along rays through the box, normalised to [0, 1]^3 (as bench/nn_bench.cc's)."""
    o = torch.nn.functional.normalize(torch.randn(RAYS, 3, generator=gen), dim=-1) * 3.0
    target = (torch.rand(RAYS, 3, generator=gen) - 0.5) * 0.6
    d = torch.nn.functional.normalize(target - o, dim=-1)
    # The box [-1, 1]^3 along each ray (slab test); every ray passes near the centre.
    t0, t1 = (-1.0 - o) / d, (1.0 - o) / d
    near = torch.minimum(t0, t1).amax(-1, keepdim=True)
    far = torch.maximum(t0, t1).amin(-1, keepdim=True)
    k = (torch.arange(SAMPLES_PER_RAY, dtype=torch.float32) + 0.5) / SAMPLES_PER_RAY
    t = near + k[None] * (far - near)  # [rays, samples]
    x = (o[:, None, :] + t[..., None] * d[:, None, :]).clamp(-1.0, 1.0).reshape(-1, 3)
    return 0.5 * (x + 1.0)


def rate(fn, steps, warmup):
    """samples/s of fn() over `steps` timed calls after `warmup` untimed ones."""
    for _ in range(warmup):
        fn()
    t0 = time.perf_counter()
    for _ in range(steps):
        fn()
    return RAYS * SAMPLES_PER_RAY * steps / (time.perf_counter() - t0)


def kernels(gen):
    """(benchmark name, function) for every kernel, each named as its icef_bench counterpart."""
    n = RAYS * SAMPLES_PER_RAY
    grid, pos = HashGrid(), make_positions(gen)
    d_feat = torch.full((n, LEVELS * FEATURES), 1e-3)

    def grid_forward():
        with torch.no_grad():
            grid(pos)

    def grid_forward_backward():
        grid.table.grad = None
        p = pos.clone().requires_grad_(True)
        grid(p).backward(d_feat)

    out = [("BM_HashGridForward", grid_forward), ("BM_HashGridForwardBackward", grid_forward_backward)]
    for k, (_, widths, sigmoid) in enumerate(MLPS):
        net = mlp(widths, sigmoid)
        x = (torch.arange(n * widths[0]) % 17 - 8).float().reshape(n, widths[0]) / 8.0
        dy = torch.full((n, widths[-1]), 1e-3)

        def forward(net=net, x=x):
            with torch.no_grad():
                net(x)

        def forward_backward(net=net, x=x, dy=dy):
            net.zero_grad(set_to_none=True)
            xi = x.clone().requires_grad_(True)  # the input gradient too, as Mlp::Backward's dx
            net(xi).backward(dy)

        out += [(f"BM_MlpForward/{k}", forward), (f"BM_MlpForwardBackward/{k}", forward_backward)]
    return out


def cpp_rates(path):
    """samples/s of the kernel benchmarks in icef_bench's JSON, by name without the run options."""
    rates = {}
    for b in json.load(open(path))["benchmarks"]:
        name = "/".join(part for part in b["name"].split("/")
                        if not part.startswith("min_time:") and part != "real_time")
        if (name.startswith("BM_HashGrid") or name.startswith("BM_Mlp")) and "samples_per_second" in b:
            rates[name] = b["samples_per_second"]
    return rates


def main():
    ap = argparse.ArgumentParser(description="The engine's kernels in PyTorch (samples/s).")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=8, help="timed calls per kernel (after --warmup calls)")
    ap.add_argument("--warmup", type=int, default=2)
    ap.add_argument("--json", help="write {kernels: {name: samples_per_second}, ...} here")
    ap.add_argument("--cpp-results", help="icef_bench's --benchmark_out JSON of the same run: print and record "
                                          "each kernel's samples/s over PyTorch's")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    gen = torch.Generator().manual_seed(0)
    result = {"threads": args.threads, "steps": args.steps, "samples_per_step": RAYS * SAMPLES_PER_RAY,
              "torch_version": torch.__version__, "kernels": {}, "ratios": {},
              "mlp_weights": [sum(a * b for a, b in zip(w[:-1], w[1:])) for _, w, _ in MLPS],
              "grid_params": HashGrid().table.numel()}
    for name, fn in kernels(gen):
        result["kernels"][name] = rate(fn, args.steps, args.warmup)
        print(f"torch_reference_bench: {name}: {result['kernels'][name] / 1e3:.1f} k samples/s "
              f"({args.threads} threads, PyTorch {torch.__version__})")
    if args.cpp_results:
        for name, cpp in sorted(cpp_rates(args.cpp_results).items()):
            if name not in result["kernels"]:
                continue
            torch_rate = result["kernels"][name]
            result["ratios"][name] = cpp / torch_rate
            print(f"torch_reference_bench: {name} / PyTorch = {cpp / 1e3:.1f} k / {torch_rate / 1e3:.1f} k = "
                  f"{result['ratios'][name]:.1f}x")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
