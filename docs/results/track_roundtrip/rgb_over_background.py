#!/usr/bin/env python3
"""Turns an icef synth dataset into one of NerFace's kind: RGB frames (no alpha) in front of a
background image, bg/00050.png, named by background_file_path. The background is procedural
(blurred colour noise and a few bars), drawn from SEED. Usage: rgb_over_background.py SRC DST SEED
(needs numpy and PIL; background_outlines.json was measured with it)."""
import json,sys,os,shutil,numpy as np
from PIL import Image, ImageFilter
src,dst,seed=sys.argv[1],sys.argv[2],int(sys.argv[3])
shutil.rmtree(dst,ignore_errors=True); os.makedirs(dst+'/images'); os.makedirs(dst+'/bg')
rng=np.random.default_rng(seed)
w=h=128
# a structured background: blurred colour noise plus a few bars
bg=rng.random((16,16,3))
bgi=Image.fromarray((bg*255).astype(np.uint8)).resize((w,h),Image.BICUBIC).filter(ImageFilter.GaussianBlur(2))
B=np.asarray(bgi).astype(np.float32)/255
for i in range(6):
    x=rng.integers(0,w); B[:,x:x+3]=rng.random(3)
Image.fromarray((B*255).astype(np.uint8)).save(dst+'/bg/00050.png')
B=np.asarray(Image.open(dst+'/bg/00050.png')).astype(np.float32)/255
for split in ['train','test']:
    d=json.load(open(f'{src}/transforms_{split}.json'))
    for f in d['frames']:
        im=np.asarray(Image.open(f'{src}/'+f['file_path'])).astype(np.float32)/255
        a=im[...,3:4]; rgb=im[...,:3]*a+B*(1-a)
        Image.fromarray((np.clip(rgb,0,1)*255+0.5).astype(np.uint8)).save(f'{dst}/'+f['file_path'])
        if f.get('neutral_file_path'):
            im=np.asarray(Image.open(f'{src}/'+f['neutral_file_path'])).astype(np.float32)/255
            a=im[...,3:4]; rgb=im[...,:3]*a+B*(1-a)
            Image.fromarray((np.clip(rgb,0,1)*255+0.5).astype(np.uint8)).save(f'{dst}/'+f['neutral_file_path'])
    d['background_file_path']='bg/00050.png'
    json.dump(d,open(f'{dst}/transforms_{split}.json','w'),indent=1)
