#!/usr/bin/env python3
"""Writes the reliability corpus (tests/reliability/base and tests/reliability/cases).

Run once after changing a case; the output is committed. Each case directory holds a case.txt
(what the runner does and expects, see README.md) and the files that replace or join the files of
the base dataset (a small valid dataset in base/). Standard library only (PNGs are encoded here).
"""
import json
import os
import shutil
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
W, H = 8, 8


def png(width, height, channels, depth=8, seed=0):
    """A PNG of a smooth pattern; channels 1 (grey), 2 (grey+alpha), 3 (RGB), 4 (RGBA)."""
    colour_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    maxv = (1 << depth) - 1
    rows = b""
    for y in range(height):
        row = b"\x00"
        for x in range(width):
            for c in range(channels):
                v = ((x * 37 + y * 61 + c * 101 + seed * 13) % 256) / 255.0
                if channels in (2, 4) and c == channels - 1:
                    v = 1.0
                q = int(round(v * maxv))
                row += struct.pack(">H", q) if depth == 16 else bytes([q])
        rows += row

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b"")


def frame(i, split, tx, expression, **extra):
    f = {"file_path": f"images/{split}_{i:03d}.png",
         "transform_matrix": [[1, 0, 0, tx], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1]],
         "expression": expression}
    f.update(extra)
    return f


def header():
    return {"w": W, "h": H, "fl_x": 10.0, "fl_y": 10.0, "cx": 4.0, "cy": 4.0,
            "aabb": [[-1, -1, -1], [1, 1, 1]], "expression_dim": 3,
            "expression_names": ["jaw_open", "smile", "brow_raise"], "background": [1, 1, 1],
            "tier_thresholds": [0.5, 1.0]}


def base_train():
    d = header()
    d["frames"] = [frame(0, "train", -0.2, [0, 0, 0]), frame(1, "train", 0.0, [1, 0, 0]),
                   frame(2, "train", 0.2, [0, 1, 0])]
    return d


def base_test():
    d = header()
    d["frames"] = [frame(0, "test", 0.1, [1, 0, 0], delta=0.0, tier="observed"),
                   frame(1, "test", -0.1, [0, 0, 2], delta=2.0, tier="far")]
    return d


def dump(obj):
    return json.dumps(obj, indent=1) + "\n"


CASES = []


def case(name, what, run, expect, files=None, remove=None, exit_code=1, needs=None, mutate=None, leaves=None):
    CASES.append(dict(name=name, what=what, run=run, expect=expect, files=files or {}, remove=remove or [],
                      exit=exit_code, needs=needs, mutate=mutate, leaves=leaves))


def edited(split, fn):
    d = base_train() if split == "train" else base_test()
    fn(d)
    return dump(d)


def define_cases():
    t = "transforms_train.json"
    info = "info {data}"
    # --- dataset JSON -----------------------------------------------------------------------
    case("json_truncated", "transforms_train.json cut off mid-way (malformed JSON)", info, [t],
         {t: dump(base_train())[:300]})
    case("json_empty", "zero-size transforms_train.json", info, [t], {t: ""})
    case("json_top_level_array", "top-level JSON array instead of an object", info, [t], {t: "[1, 2, 3]\n"})
    case("wrong_type_fl_x", "fl_x is a string (\"10\")", info, [t, "fl_x"],
         {t: edited("train", lambda d: d.update(fl_x="10"))})
    case("frames_not_array", "frames is an object", info, [t, "frames"],
         {t: edited("train", lambda d: d.update(frames={"0": 1}))})
    case("nan_expression", "NaN literal in frames[1].expression", info, [t, "frames[1]", "expression"],
         {t: edited("train", lambda d: d["frames"][1].update(expression=["__NAN__", 0, 0])).replace('"__NAN__"', "NaN")})
    case("inf_transform", "1e999 (overflows to inf) in frames[0].transform_matrix", info, [t, "1e999"],
         {t: edited("train", lambda d: d["frames"][0]["transform_matrix"][0].__setitem__(3, "__BIG__")).replace('"__BIG__"', "1e999")})
    case("expression_dim_mismatch", "frames[1].expression has 2 values, expression_dim is 3", info,
         [t, "frames[1]", "expression"],
         {t: edited("train", lambda d: d["frames"][1].update(expression=[1, 0]))})
    case("expression_names_length", "2 expression_names for expression_dim 3", info, [t, "expression_names"],
         {t: edited("train", lambda d: d.update(expression_names=["jaw_open", "smile"]))})
    case("negative_size", "w = -8", info, [t, "w"], {t: edited("train", lambda d: d.update(w=-8))})
    case("aabb_inverted", "aabb min above max", info, [t, "aabb"],
         {t: edited("train", lambda d: d.update(aabb=[[1, 1, 1], [-1, -1, -1]]))})
    case("background_range", "background colour [2, 0, 0]", info, [t, "background"],
         {t: edited("train", lambda d: d.update(background=[2, 0, 0]))})
    case("non_rigid_transform", "frames[2].transform_matrix scales by 2", info,
         [t, "frames[2]", "transform_matrix"],
         {t: edited("train", lambda d: d["frames"][2].update(
             transform_matrix=[[2, 0, 0, 0], [0, 2, 0, 0], [0, 0, 2, 3], [0, 0, 0, 1]]))})
    case("landmarks_67", "frames[0].landmarks_2d has 67 points", info, [t, "frames[0]", "landmarks_2d"],
         {t: edited("train", lambda d: d["frames"][0].update(landmarks_2d=[[1.0, 1.0]] * 67))})
    case("unknown_tier", "test frame with tier \"extreme\"", info,
         ["transforms_test.json", "frames[1]", "tier"],
         {"transforms_test.json": edited("test", lambda d: d["frames"][1].update(tier="extreme"))})
    case("negative_delta", "test frame with delta -1", info, ["transforms_test.json", "frames[0]", "delta"],
         {"transforms_test.json": edited("test", lambda d: d["frames"][0].update(delta=-1))})
    case("empty_file_path", "frames[0].file_path is \"\"", info, [t, "frames[0]", "file_path"],
         {t: edited("train", lambda d: d["frames"][0].update(file_path=""))})
    case("path_outside", "frames[0].file_path = /etc/passwd (absolute, outside the dataset)", info, [t, "frames[0]", "file_path"],
         {t: edited("train", lambda d: d["frames"][0].update(file_path="/etc/passwd"))})
    case("missing_image", "frames[1] names an image that does not exist", info, [t, "frames[1]", "file_path"],
         remove=["images/train_001.png"])
    case("missing_train_json", "no transforms_train.json in the directory", info, [t], remove=[t])
    # --- images -----------------------------------------------------------------------------
    good = png(W, H, 3, seed=1)
    case("png_zero_size", "train_000.png is a zero-size file", info, [t, "frames[0]", "train_000.png"],
         {"images/train_000.png": b""})
    # LoadDataset reads image headers and checks each file's structure (chunks, CRCs, end marker)
    # without decoding pixels, so `icef info` refuses truncated and bit-flipped PNGs.
    case("png_truncated", "train_000.png cut to its first 40 bytes (header only)", info,
         [t, "frames[0]", "train_000.png", "truncated"], {"images/train_000.png": good[:40]})
    case("png_truncated_data", "train_000.png missing its last 30 bytes (IDAT cut)", info,
         [t, "frames[0]", "train_000.png", "truncated"], {"images/train_000.png": good[:-30]})
    flipped = bytearray(good)
    flipped[good.index(b"IDAT") + 10] ^= 0x10
    case("png_bit_flip", "one bit flipped inside train_000.png's pixel data (IDAT)", info,
         [t, "frames[0]", "train_000.png", "CRC"], {"images/train_000.png": bytes(flipped)})
    # JPEG: the committed 8x8 seed of the image fuzzer, named in the JSON as train_000.jpg.
    with open(os.path.join(HERE, "..", "..", "fuzz", "corpus", "image", "rgb_8x8.jpg"), "rb") as f:
        jpeg = f.read()
    jpeg_json = edited("train", lambda d: d["frames"][0].update(file_path="images/train_000.jpg"))
    case("jpeg_truncated", "train_000.jpg cut in half", info, [t, "frames[0]", "train_000.jpg", "truncated"],
         {t: jpeg_json, "images/train_000.jpg": jpeg[:len(jpeg) // 2]})
    dht = bytearray(jpeg)
    at = jpeg.index(b"\xff\xc4") + 5  # the 16 code counts of the first Huffman table
    dht[at:at + 16] = bytes([17] * 16)  # 272 codes: stb_image wrote past its table here
    case("jpeg_huffman_overflow", "train_000.jpg with a Huffman table of 272 codes (at most 256)", info,
         [t, "frames[0]", "train_000.jpg", "Huffman"], {t: jpeg_json, "images/train_000.jpg": bytes(dht)})
    case("png_not_an_image", "train_000.png holds text", info, [t, "frames[0]", "train_000.png"],
         {"images/train_000.png": b"this is not a PNG\n"})
    case("png_16bit", "train_000.png is a 16-bit RGB PNG (supported: read as [0, 1] floats)", info, [],
         {"images/train_000.png": png(W, H, 3, depth=16, seed=1)}, exit_code=0)
    case("png_grey", "train_000.png has 1 channel (supported: grey is repeated into RGB)", info, [],
         {"images/train_000.png": png(W, H, 1, seed=1)}, exit_code=0)
    case("png_grey_alpha", "train_000.png has 2 channels (supported: grey + alpha becomes RGBA)", info, [],
         {"images/train_000.png": png(W, H, 2, seed=1)}, exit_code=0)
    case("png_size_mismatch", "train_001.png is 8x6, the JSON says 8x8", info, [t, "frames[1]", "train_001.png"],
         {"images/train_001.png": png(W, 6, 3, seed=2)})
    # --- CLI values ---------------------------------------------------------------------------
    case("synth_negative_k", "icef synth --k -3", "synth --out {out} --k -3 --res 16", ["k", "-3"])
    case("synth_zero_res", "icef synth --res 0", "synth --out {out} --res 0", ["res"])
    case("synth_nan_threshold", "icef synth --near nan", "synth --out {out} --res 16 --near nan", ["near"])
    case("import_malformed", "icef import of a dataset whose JSON is cut off", "import {data} --out {out}",
         [t], {t: dump(base_train())[:300]})
    # --- run configs (icef train) -------------------------------------------------------------
    cfg = "train {synth} --out {out} --config {data}/config.json"
    case("config_unknown_key", "run config with a misspelt key train.lamda_id", cfg, ["config.json", "lamda_id"],
         {"config.json": '{"train": {"steps": 2, "lamda_id": 0.1}}\n'}, needs="train")
    case("config_nan_lambda", "run config with train.lambda_id = NaN", cfg, ["config.json", "lambda_id"],
         {"config.json": '{"train": {"steps": 2, "lambda_id": NaN}}\n'}, needs="train")
    case("config_negative_lambda", "run config with train.lambda_id = -1", cfg, ["config.json", "lambda_id"],
         {"config.json": '{"train": {"steps": 2, "lambda_id": -1}}\n'}, needs="train")
    case("config_wrong_type", "run config with train.steps = \"ten\"", cfg, ["config.json", "steps"],
         {"config.json": '{"train": {"steps": "ten"}}\n'}, needs="train")
    case("config_unknown_section", "run config with a section \"optimizer\"", cfg, ["config.json", "optimizer"],
         {"config.json": '{"optimizer": {"lr": 1}}\n'}, needs="train")
    case("config_bad_nonfinite_policy", "run config with train.on_nonfinite = \"ignore\"", cfg,
         ["config.json", "on_nonfinite"], {"config.json": '{"train": {"steps": 2, "on_nonfinite": "ignore"}}\n'},
         needs="train")
    case("train_malformed_dataset", "icef train on a dataset with a zero-size image", "train {data} --out {out}",
         ["train_000.png"], {"images/train_000.png": b""}, needs="train")
    case("train_truncated_png", "icef train on a dataset whose train_000.png is cut to 40 bytes",
         "train {data} --out {out}", ["train_000.png"], {"images/train_000.png": png(W, H, 3, seed=1)[:40]},
         needs="train")
    # --- checkpoints (a tiny model trained once per run, then damaged) ------------------------
    render = "render {model} --out {out}"
    case("ckpt_truncated", "checkpoint.icef cut to half its size", render, ["checkpoint.icef", "truncated"],
         needs="render", mutate="truncate-half")
    case("ckpt_bit_flip", "one bit flipped in the middle of checkpoint.icef", render,
         ["checkpoint.icef", "checksum"], needs="render", mutate="flip-bit")
    case("ckpt_zero_size", "zero-size checkpoint.icef", render, ["checkpoint.icef"], needs="render",
         mutate="empty")
    case("ckpt_not_checkpoint", "checkpoint.icef replaced by a PNG", render, ["checkpoint.icef", "magic"],
         needs="render", mutate="png")
    case("ckpt_missing", "model directory without checkpoint.icef", render, ["checkpoint.icef"],
         needs="render", mutate="delete")
    # Resealed checkpoints (edit_checkpoint.py): the container checksum passes, the content is wrong.
    case("ckpt_step_negative", "checkpoint.icef with trainer.step = -1 (resealed)", render,
         ["checkpoint.icef", "trainer.step", "-1"], needs="render", mutate="set-json trainer step -1")
    case("ckpt_step_fraction", "checkpoint.icef with trainer.step = 2.5 (resealed)", render,
         ["checkpoint.icef", "trainer.step", "2.5"], needs="render", mutate="set-json trainer step 2.5")
    case("ckpt_step_huge", "checkpoint.icef with trainer.step = 1e300 (resealed)", render,
         ["checkpoint.icef", "trainer.step"], needs="render", mutate="set-json trainer step 1e300")
    case("ckpt_config_edited", "checkpoint.icef whose config says train.lambda_id = 0.5 (resealed; hash kept)",
         render, ["checkpoint.icef", "config_hash"], needs="render",
         mutate="set-json config train.lambda_id 0.5")
    case("ckpt_config_hash_wrong", "checkpoint.icef with trainer.config_hash = 12345 (resealed)", render,
         ["checkpoint.icef", "config_hash"], needs="render", mutate="set-json trainer config_hash 12345")
    resume = "train {synth} --out {model} --resume"
    tiny = json.load(open(os.path.join(HERE, "tiny_config.json")))
    tiny["train"]["lambda_id"] = 0.5
    case("resume_other_config", "icef train --resume with a --config whose train.lambda_id differs", resume +
         " --config {data}/config.json", ["checkpoint.icef", "config.json", "train.lambda_id"],
         {"config.json": json.dumps(tiny) + "\n"}, needs="train")
    case("resume_set_method", "icef train --resume --set model.method=warp", resume + " --set model.method=warp",
         ["checkpoint.icef", "model.method"], needs="train")
    case("render_unknown_expression", "icef render --set-expression grin=1 (no such expression)",
         "render {model} --out {out} --set-expression grin=1", ["grin"], needs="render")
    case("render_wrong_expression_length", "icef render --beta with 2 values for expression_dim 11",
         "render {model} --out {out} --beta 0.1,0.2", ["beta", "11"], needs="render")


def main():
    base = os.path.join(HERE, "base")
    shutil.rmtree(base, ignore_errors=True)
    os.makedirs(os.path.join(base, "images"))
    with open(os.path.join(base, "transforms_train.json"), "w") as f:
        f.write(dump(base_train()))
    with open(os.path.join(base, "transforms_test.json"), "w") as f:
        f.write(dump(base_test()))
    for split, n in (("train", 3), ("test", 2)):
        for i in range(n):
            with open(os.path.join(base, "images", f"{split}_{i:03d}.png"), "wb") as f:
                f.write(png(W, H, 3, seed=i + (10 if split == "test" else 0)))
    define_cases()
    cases_dir = os.path.join(HERE, "cases")
    shutil.rmtree(cases_dir, ignore_errors=True)
    for c in CASES:
        d = os.path.join(cases_dir, c["name"])
        os.makedirs(d)
        lines = [f"what: {c['what']}", f"run: {c['run']}", f"exit: {c['exit']}"]
        if c["expect"]:
            lines.append("expect: " + " | ".join(c["expect"]))
        if c["remove"]:
            lines.append("remove: " + " ".join(c["remove"]))
        if c["needs"]:
            lines.append(f"needs: {c['needs']}")
        if c["mutate"]:
            lines.append(f"mutate: {c['mutate']}")
        if c["leaves"]:
            lines.append(f"leaves: {c['leaves']}")
        with open(os.path.join(d, "case.txt"), "w") as f:
            f.write("\n".join(lines) + "\n")
        for rel, content in c["files"].items():
            p = os.path.join(d, "files", rel)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            with open(p, "wb") as f:
                f.write(content.encode() if isinstance(content, str) else content)
    print(f"wrote base/ and {len(CASES)} cases")


if __name__ == "__main__":
    main()
