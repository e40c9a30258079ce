#!/usr/bin/env python3
# The reference training step (src/icef/nn/reference_model.h, docs/design.md §7) written in plain
# PyTorch, so that `make bench` can quote BM_ReferenceTrainStep against PyTorch measured in the same
# run on the same cores. Same modules and sizes, same batch shape, same loss and optimiser:
#
#   g   = DeformMlp([freq6(x) (39), beta (16)])   55 -> 64 -> 64 -> 64 -> 3, no biases
#   p   = (x + g + 1) / 2
#   f   = HashGrid(p)                             L = 16, F = 2, T = 2^19, resolutions 16 .. 1024
#   h   = DensityMlp(f)                           32 -> 64 -> 16;  sigma = exp(h_0)
#   rgb = ColourMlp([h, SH4(d)])                  32 -> 64 -> 64 -> 3 (sigmoid)
#   loss = mean(|rgb - target|^2 + 0.01 sigma);   Adam (grid lr 1e-2, MLPs 1e-3, betas 0.9 / 0.99,
#   eps 1e-15); 4096 rays x 32 samples per step.
#
# "Tuned" as far as eager PyTorch on a CPU goes: the hash grid is vectorised over samples and
# corners per level (the pure-PyTorch fallback of the usual NeRF code bases), Adam uses the
# multi-tensor (foreach) path, the batch is made once, and no autograd graph is kept past a step.
#
#   python3 scripts/torch_reference_bench.py [--threads 2] [--steps 8] [--json OUT]
#
# Prints samples/s and writes them to OUT (JSON) when asked. Needs Debian's python3-torch
# (`scripts/install-deps.sh --bench` installs it, with OpenBLAS as its BLAS).
import argparse, json, math, sys, time

try:
    import torch
except ImportError:
    sys.exit("torch_reference_bench: PyTorch is not installed (scripts/install-deps.sh --bench installs python3-torch)")

RAYS, SAMPLES_PER_RAY, BETA_DIMS = 4096, 32, 16
LEVELS, FEATURES, LOG2_T, BASE_RES, FINEST_RES = 16, 2, 19, 16, 1024
PRIME1, PRIME2 = 2654435761, 805459861


def mlp(widths, out_act=None):
    layers = []
    for i in range(len(widths) - 1):
        layers.append(torch.nn.Linear(widths[i], widths[i + 1], bias=False))
        if i + 2 < len(widths):
            layers.append(torch.nn.ReLU())
    if out_act is not None:
        layers.append(out_act)
    return torch.nn.Sequential(*layers)


def freq_encode(x, n=6):
    out = [x]
    for k in range(n):
        a = (2.0 ** k) * math.pi * x
        out += [torch.sin(a), torch.cos(a)]
    return torch.cat(out, dim=-1)


def sh4(d):
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    xx, yy, zz, xy, yz, xz = x * x, y * y, z * z, x * y, y * z, x * z
    return torch.stack([
        torch.full_like(x, 0.28209479177387814),
        -0.48860251190291987 * y, 0.48860251190291987 * z, -0.48860251190291987 * x,
        1.0925484305920792 * xy, -1.0925484305920792 * yz, 0.94617469575755997 * zz - 0.31539156525251999,
        -1.0925484305920792 * xz, 0.54627421529603959 * (xx - yy),
        0.59004358992664352 * y * (-3.0 * xx + yy), 2.8906114426405538 * xy * z,
        0.45704579946446572 * y * (1.0 - 5.0 * zz), 0.3731763325901154 * z * (5.0 * zz - 3.0),
        0.45704579946446572 * x * (1.0 - 5.0 * zz), 1.4453057213202769 * z * (xx - yy),
        0.59004358992664352 * x * (-xx + 3.0 * yy)], dim=-1)


class HashGrid(torch.nn.Module):
    def __init__(self, sparse):
        super().__init__()
        self.sparse = sparse
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
            cell = x.floor().long().clamp(max=r - 1)
            frac = x - cell
            v = cell[:, None, :] + self.corners[None]  # [n, 8, 3]
            if dense:
                idx = v[..., 0] + v[..., 1] * (r + 1) + v[..., 2] * (r + 1) ** 2
            else:
                idx = (v[..., 0] ^ (v[..., 1] * PRIME1) ^ (v[..., 2] * PRIME2)) & self.mask
            w = torch.where(self.corners[None].bool(), frac[:, None, :], 1.0 - frac[:, None, :]).prod(-1)
            if self.sparse:
                vals = torch.nn.functional.embedding(idx + offset, self.table, sparse=True)  # [n, 8, F]
            else:
                vals = self.table[idx + offset]  # (its backward, index_put_, beats embedding's here)
            feats.append((w[..., None] * vals).sum(1))
        return torch.cat(feats, dim=-1)


class ReferenceModel(torch.nn.Module):
    def __init__(self, sparse):
        super().__init__()
        self.deform = mlp([39 + BETA_DIMS, 64, 64, 64, 3])
        self.grid = HashGrid(sparse)
        self.density = mlp([LEVELS * FEATURES, 64, 16])
        self.colour = mlp([32, 64, 64, 3], torch.nn.Sigmoid())

    def forward(self, x, d, beta):
        g = self.deform(torch.cat([freq_encode(x), beta], dim=-1))
        h = self.density(self.grid((x + g + 1.0) / 2.0))
        sigma = torch.exp(h[:, :1])
        rgb = self.colour(torch.cat([h, sh4(d)], dim=-1))
        return rgb, sigma


def make_batch(gen):
    n = RAYS * SAMPLES_PER_RAY
    x = torch.rand(n, 3, generator=gen) * 2.0 - 1.0
    d = torch.nn.functional.normalize(torch.randn(RAYS, 3, generator=gen), dim=-1).repeat_interleave(SAMPLES_PER_RAY, 0)
    beta = (torch.rand(RAYS, BETA_DIMS, generator=gen) * 2.0 - 1.0).repeat_interleave(SAMPLES_PER_RAY, 0)
    target = torch.rand(n, 3, generator=gen)
    return x, d, beta, target


def cpp_rates(path):
    """samples/s of BM_ReferenceTrainStep and of the default BM_TrainStep in icef_bench's JSON."""
    rates = {}
    for b in json.load(open(path))["benchmarks"]:
        if b["name"] == "BM_ReferenceTrainStep":
            rates["BM_ReferenceTrainStep"] = b["samples_per_second"]
        elif b["name"].startswith("BM_TrainStep/bf16:1/composited:1"):
            rates["BM_TrainStep"] = b["samples/s"]
    return rates


def main():
    ap = argparse.ArgumentParser(description="The reference training step in PyTorch (samples/s).")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=8, help="timed steps (after --warmup steps)")
    ap.add_argument("--warmup", type=int, default=2)
    ap.add_argument("--json", help="write {samples_per_second, ...} here")
    ap.add_argument("--cpp-results", help="icef_bench's --benchmark_out JSON of the same run: print and record "
                                          "BM_ReferenceTrainStep's and BM_TrainStep's samples/s over PyTorch's")
    ap.add_argument("--sparse-grid-adam", action="store_true",
                    help="sparse table gradients and SparseAdam, as the C++ step's sparse Adam (slower in "
                         "PyTorch 1.13: 20 k against 50-80 k samples/s dense)")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    gen = torch.Generator().manual_seed(0)
    sparse = args.sparse_grid_adam
    model = ReferenceModel(sparse)
    x, d, beta, target = make_batch(gen)
    mlps = [p for n, p in model.named_parameters() if not n.startswith("grid.")]
    adam = dict(betas=(0.9, 0.99), eps=1e-15)
    if sparse:  # the table's rows without gradient keep their moments, as the C++ step's sparse Adam
        opts = [torch.optim.SparseAdam([model.grid.table], lr=1e-2, **adam),
                torch.optim.Adam(mlps, lr=1e-3, foreach=True, **adam)]
    else:
        opts = [torch.optim.Adam([{"params": [model.grid.table], "lr": 1e-2}, {"params": mlps, "lr": 1e-3}],
                                 foreach=True, **adam)]

    def step():
        for opt in opts:
            opt.zero_grad(set_to_none=True)
        rgb, sigma = model(x, d, beta)
        loss = ((rgb - target) ** 2).sum(-1).mean() + 0.01 * sigma.mean()
        loss.backward()
        for opt in opts:
            opt.step()
        return float(loss)

    for _ in range(args.warmup):
        step()
    t0 = time.perf_counter()
    for _ in range(args.steps):
        loss = step()
    wall = time.perf_counter() - t0
    n = RAYS * SAMPLES_PER_RAY
    result = {"samples_per_second": n * args.steps / wall, "seconds_per_step": wall / args.steps,
              "steps": args.steps, "threads": args.threads, "samples_per_step": n, "loss": loss,
              "grid_adam": "sparse" if sparse else "dense", "torch_version": torch.__version__,
              "mlp_weights": sum(p.numel() for p in mlps), "grid_params": model.grid.table.numel()}
    print(f"torch_reference_bench: {result['samples_per_second'] / 1e3:.1f} k samples/s "
          f"({result['seconds_per_step']:.2f} s per step of {n} samples, {args.threads} threads, PyTorch {torch.__version__})")
    if args.cpp_results:
        for name, key in cpp_rates(args.cpp_results).items():
            result["ratio_" + name] = key / result["samples_per_second"]
            print(f"torch_reference_bench: {name} / PyTorch = {key / 1e3:.1f} k / "
                  f"{result['samples_per_second'] / 1e3:.1f} k = {result['ratio_' + name]:.1f}x")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
