// Winograd's minimal filtering F(4x4, 3x3) (Lavin and Gray, "Fast Algorithms for
// Convolutional Neural Networks", CVPR 2016): a 3x3 convolution, stride 1, computed 4x4
// outputs at a time from a 6x6 window of the input as
//
//   Y = A^T [ (G g G^T) . (B^T d B) ] A        (. elementwise, per input channel, summed)
//
// with g a 3x3 filter, d the 6x6 window, U = G g G^T the transformed filter (made once,
// at load) and V = B^T d B the transformed window. Summing U . V over the input channels
// is, for each of the 36 positions xi of the 6x6 transform, one matrix product
// [tiles x in_c] x [in_c x out_c]: 36 products of 1/4 of the multiply-adds a direct 3x3
// convolution needs (36 against 16 x 9 per tile and channel pair), on the GEMM
// micro-kernel. Conv2d's winograd path (kernels/conv.h) runs it; the table's
// winograd_input and winograd_output kernels (kernels/kernel_list.def) do the window and
// output transforms.
//
// The matrices come from the Toom-Cook construction on the points (0, 1, -1, 1/2, -2)
// and infinity. The usual points (0, 1, -1, 2, -2) give the same speed but twice the
// rounding error: summing over 384 input channels in float, the largest error of a tile
// was 8.7e-6 of its largest output with those and 4.2e-6 with these (a one-off numpy
// simulation of the float32 arithmetic, against float64 direct convolution). The
// choice of 1/2 for 2 follows Barabasz, Anderson, Soodhalter and Gregg, "Error analysis
// and improving the accuracy of Winograd convolution for deep neural networks", ACM
// TOMS 2020, which found point sets with reciprocals more accurate for F(4, 3).
#pragma once

namespace ampi::winograd {

constexpr int kTile = 4;     // outputs per tile side
constexpr int kWindow = 6;   // inputs per window side: kTile + 3 - 1
constexpr int kPositions = kWindow * kWindow;  // transform positions xi = 6 * i + j

// V = B^T d B: row i of B^T combines the window's six rows (then, transposed, its columns).
constexpr double kInputT[kWindow][kWindow] = {
    {1, -1.5, -2, 1.5, 1, 0},   //
    {0, -1, 0.5, 2.5, 1, 0},    //
    {0, 1, -2.5, 0.5, 1, 0},    //
    {0, -2, -1, 2, 1, 0},       //
    {0, 0.5, -1, -0.5, 1, 0},   //
    {0, 1, -1.5, -2, 1.5, 1}};

// U = G g G^T: row i of G evaluates the filter polynomial at point i, divided by the
// product of that point's distances to the others (the last row: the leading tap).
constexpr double kFilter[kWindow][3] = {
    {1, 0, 0},                                    //
    {1.0 / 3, 1.0 / 3, 1.0 / 3},                  //
    {-1.0 / 3, 1.0 / 3, -1.0 / 3},                //
    {-16.0 / 15, -8.0 / 15, -4.0 / 15},           //
    {1.0 / 15, -2.0 / 15, 4.0 / 15},              //
    {0, 0, 1}};

// Y = A^T M A: row k of A^T holds the points' k-th powers (the last column: infinity).
constexpr double kOutputT[kTile][kWindow] = {
    {1, 1, 1, 1, 1, 0},         //
    {0, 1, -1, 0.5, -2, 0},     //
    {0, 1, 1, 0.25, 4, 0},      //
    {0, 1, -1, 0.125, -8, 1}};

}  // namespace ampi::winograd
