# Network inference: forward-only CNN layers and the TF.js weights reader, for pretrained networks
# (eval/'s face-identity ResNet and LPIPS). Needs only core and io.
icef_module(infer DEPS icef_io)
