"""The depth loss of the paper (section "Implementation details"):

    L       = L_data + 0.5 * L_grad                     for each output, summed over outputs
    L_data  = mean |y^ - y|
    L_grad  = sum_{s=0..3} mean |grad_x(y^_s - y_s)| + mean |grad_y(y^_s - y_s)|

where y is the target disparity normalised per image to [0, 10] and brought to the
output's resolution, and y^_s, y_s are prediction and target down-scaled by 2^s. The
down-scaling is a 2^s x 2^s average (area) pooling; since it is linear, pooling the
difference equals the difference of the pooled maps. A scale whose map would be smaller
than 2 pixels on a side has no gradient to measure and is skipped (only on tiny inputs).

invariant=True (train_depth.py --loss invariant, ours, not the paper's) puts both y^ and
y through normalise_median_mad first, as MiDaS does (Ranftl et al. 2020, "scale- and
shift-invariant losses"): the network no longer has to guess where the nearest pixel of
a scene lies, which the [0, 10] target asks of it.
"""
from __future__ import annotations

import torch
import torch.nn.functional as F

GRAD_WEIGHT = 0.5
GRAD_SCALES = 4
TARGET_RANGE = 10.0
# the mean absolute deviation normalise_median_mad brings maps to: about that of a synthetic
# scene's target normalised to [0, TARGET_RANGE], so the weights of the losses beside it keep their sense
INVARIANT_SPREAD = 2.25


def normalise_target(disparity: torch.Tensor, eps: float = 1e-6) -> torch.Tensor:
    """Per-image min-max to [0, TARGET_RANGE]; [N, 1, H, W]. A constant map becomes 0."""
    flat = disparity.flatten(1)
    lo = flat.min(dim=1).values.view(-1, 1, 1, 1)
    hi = flat.max(dim=1).values.view(-1, 1, 1, 1)
    return TARGET_RANGE * (disparity - lo) / (hi - lo).clamp_min(eps)


def normalise_median_mad(x: torch.Tensor, eps: float = 1e-6) -> torch.Tensor:
    """Per image of [N, 1, H, W]: minus its median, over its mean absolute deviation from
    it, times INVARIANT_SPREAD; the same for any a * x + b with a > 0."""
    median = x.flatten(1).median(dim=1).values.view(-1, 1, 1, 1)
    spread = (x - median).abs().flatten(1).mean(dim=1).view(-1, 1, 1, 1)
    return INVARIANT_SPREAD * (x - median) / spread.clamp_min(eps)


def resize_target(target: torch.Tensor, size) -> torch.Tensor:
    """Area down-scaling of the target to an output's (h, w), an integer factor."""
    if tuple(target.shape[-2:]) == tuple(size):
        return target
    factor = target.shape[-2] // size[0]
    if factor * size[0] != target.shape[-2] or factor * size[1] != target.shape[-1]:
        raise ValueError(f"target {tuple(target.shape[-2:])} is not an integer multiple of {tuple(size)}")
    return F.avg_pool2d(target, factor)


def gradient_loss(diff: torch.Tensor, scales: int = GRAD_SCALES) -> torch.Tensor:
    total = diff.new_zeros(())
    for s in range(scales):
        d = F.avg_pool2d(diff, 2 ** s) if s else diff
        if d.shape[-1] < 2 or d.shape[-2] < 2:
            break
        total = total + (d[..., :, 1:] - d[..., :, :-1]).abs().mean()
        total = total + (d[..., 1:, :] - d[..., :-1, :]).abs().mean()
    return total


def output_loss(pred: torch.Tensor, target: torch.Tensor):
    """(L, L_data, L_grad) for one output and a target already at its resolution."""
    diff = pred - target
    data = diff.abs().mean()
    grad = gradient_loss(diff)
    return data + GRAD_WEIGHT * grad, data, grad


def depth_loss(outputs, disparity: torch.Tensor, invariant: bool = False):
    """Sum of the per-output losses. outputs: the network's list of [N, 1, h, w] maps;
    disparity: the raw target [N, 1, H, W] at the finest output's size; invariant: both
    normalised by median and deviation instead (module docstring). Returns the total and
    a dict of the parts (floats) for the log."""
    target = disparity if invariant else normalise_target(disparity)
    total = disparity.new_zeros(())
    parts = {"data": 0.0, "grad": 0.0}
    for pred in outputs:
        scaled = resize_target(target, pred.shape[-2:])
        if invariant:  # each output with the target at its own size, so that pooling commutes
            pred, scaled = normalise_median_mad(pred), normalise_median_mad(scaled)
        loss, data, grad = output_loss(pred, scaled)
        total = total + loss
        parts["data"] += float(data)
        parts["grad"] += float(grad)
    return total, parts
