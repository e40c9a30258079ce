#!/usr/bin/env python3
# The leave-one-out table of docs/results/priors_validation.md (diverse suite) from the runs of one
# validation bench per variant: BASE/<variant>/runs/<run>/metrics.json (default base:
# docs/results/priors_diverse). Each variant was made by
#   icef bench --validation --methods icef --res 128 --steps 1000 --test-views 2 --novel-per-tier 1 \
#     --out BASE/<variant> [--set KEY=VALUE]
import json, os, sys
base=sys.argv[1] if len(sys.argv) > 1 else 'docs/results/priors_diverse'
variants=[('default','all defaults'),('no-supersample','`model.render.supersample=1` (one ray per pixel in renders)'),
          ('no-hull','`model.visual_hull.enabled=false`'),('no-distortion','`train.lambda_distortion=0`'),
          ('no-symmetry','`train.lambda_symmetry=0`'),('no-occlusion','`train.lambda_occlusion=0`')]
def load(v):
    out={}
    d=f'{base}/{v}/runs'
    if not os.path.isdir(d): return out
    for r in sorted(os.listdir(d)):
        p=f'{d}/{r}/metrics.json'
        if not os.path.exists(p): continue
        m=json.load(open(p)); m=m.get('metrics',m)
        seed=int(r.split('_')[0][2:])
        obs=m['tiers']['observed']
        out[seed]=(m['train_fit']['face_psnr'], obs['psnr'], obs['id_distance_gt'], m['train_fit'].get('face_detail'))
    return out
data={v:load(v) for v,_ in variants}
seeds=sorted(data['default'].keys())
print('| variant | change | training-view face PSNR per seed (dB) | mean | observed PSNR per seed (dB) | mean | Δ observed vs default per seed (dB) | worst Δ | observed id_distance_gt mean | face detail mean |')
print('|---|---|---|---|---|---|---|---|---|---|')
for v,what in variants:
    d=data[v]
    if len(d)<len(seeds) or not seeds: continue
    tf=[d[s][0] for s in seeds]; ob=[d[s][1] for s in seeds]; idg=[d[s][2] for s in seeds]; det=[d[s][3] for s in seeds]
    dl=[d[s][1]-data['default'][s][1] for s in seeds]
    f=lambda xs:'/'.join('%.2f'%x for x in xs)
    print(f"| {v} | {what} | {f(tf)} | {sum(tf)/len(tf):.2f} | {f(ob)} | {sum(ob)/len(ob):.2f} | {'/'.join('%+.2f'%x for x in dl)} | {min(dl):+.2f} | {sum(idg)/len(idg):.3f} | {sum(det)/len(det):.2f} |")
