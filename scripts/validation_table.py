#!/usr/bin/env python3
# Tabulates scripts/validation_runs.sh: DIR/runs/<variant>_<seed>_t<training seed>/eval/metrics.json
# (or, for committed results, DIR/<variant>_<seed>_t<training seed>.json).
#
#   scripts/validation_table.py DIR [--variants "default no-hull ..."]
#
# Prints two markdown tables. The first is the training-seed noise of the default config: per
# identity, the observed-tier PSNR of each training seed and their spread. The second is each
# variant against the default with the same identity and training seed: Δ observed PSNR per
# identity (averaged over the training seeds both have), its mean, the worst identity, and the
# means of the training-view face PSNR, id_distance_gt and face detail.
import json, os, re, sys
from collections import defaultdict

def load(base):
    runs = defaultdict(dict)  # variant -> (seed, train seed) -> metrics
    pat = re.compile(r'^(.+)_(\d+)_t(\d+)(\.json)?$')
    root = os.path.join(base, 'runs') if os.path.isdir(os.path.join(base, 'runs')) else base
    for name in sorted(os.listdir(root)):
        m = pat.match(name)
        if not m: continue
        path = os.path.join(root, name) if m.group(4) else os.path.join(root, name, 'eval', 'metrics.json')
        if not os.path.exists(path): continue
        met = json.load(open(path))
        runs[m.group(1)][(int(m.group(2)), int(m.group(3)))] = met
    return runs

def observed(met): return met['tiers']['observed']['psnr']

def main():
    base = sys.argv[1]
    runs = load(base)
    order = ['default'] + sorted(v for v in runs if v != 'default')
    if '--variants' in sys.argv: order = sys.argv[sys.argv.index('--variants') + 1].split()
    default = runs['default']
    seeds = sorted({s for s, _ in default})
    print('| identity | observed PSNR per training seed (dB) | spread (dB) |')
    print('|---|---|---|')
    spreads = []
    for s in seeds:
        vals = [observed(default[k]) for k in sorted(default) if k[0] == s]
        spread = max(vals) - min(vals)
        if len(vals) > 1: spreads.append(spread)
        print(f"| {s} | {' / '.join('%.2f' % v for v in vals)} | {'%.2f' % spread if len(vals) > 1 else '-'} |")
    if spreads: print(f'\nMean spread between training seeds: {sum(spreads) / len(spreads):.2f} dB over {len(spreads)} identit{"y" if len(spreads) == 1 else "ies"}.')
    # The suite's mean over identities, per training seed that every identity has.
    full = [t for t in sorted({t for _, t in default}) if all((s, t) in default for s in seeds)]
    if full:
        means = ', '.join(f'seed {t}: {sum(observed(default[(s, t)]) for s in seeds) / len(seeds):.2f} dB' for t in full)
        print(f'Suite mean over the {len(seeds)} identities per training seed: {means}.')
    print()
    print('| variant | runs | Δ observed PSNR per identity (dB) | mean Δ | worst Δ | training-view face PSNR mean (default) | id_distance_gt mean (default) | face detail mean (default) |')
    print('|---|---|---|---|---|---|---|---|')
    for v in order:
        if v == 'default' or v not in runs: continue
        shared = [k for k in runs[v] if k in default]
        per_seed = {}
        for s in sorted({k[0] for k in shared}):
            ks = [k for k in shared if k[0] == s]
            per_seed[s] = sum(observed(runs[v][k]) - observed(default[k]) for k in ks) / len(ks)
        if not per_seed: continue
        def mean(f, src):  # None (e.g. no face-descriptor model installed) is left out
            vals = [f(src[k]) for k in shared if f(src[k]) is not None]
            return sum(vals) / len(vals) if vals else float('nan')
        fit = lambda m: m['train_fit']['face_psnr']
        idg = lambda m: m['tiers']['observed']['id_distance_gt']
        det = lambda m: m['train_fit']['face_detail']
        deltas = ' / '.join(f'{s}: {d:+.2f}' for s, d in per_seed.items())
        print(f'| {v} | {len(shared)} | {deltas} | {sum(per_seed.values()) / len(per_seed):+.2f} | {min(per_seed.values()):+.2f} | '
              f'{mean(fit, runs[v]):.2f} ({mean(fit, default):.2f}) | {mean(idg, runs[v]):.3f} ({mean(idg, default):.3f}) | '
              f'{mean(det, runs[v]):.2f} ({mean(det, default):.2f}) |')

if __name__ == '__main__':
    main()
