// What a gather's batch adds to one pixel, shared by final gather's
// gather_accumulate.frag and radiosity's gather_sum.frag: ray j of pixel
// (x, y) is texel (x, y + j * u_image_height) of the batch's textures, and
// with cosine-distributed rays the pixel's indirect light is throughput_1 x
// albedo_1 x the mean radiance its rays bring back, over u_total_rays.
// Needs scene.glsl and bsdf.glsl.
uniform sampler2D u_diffuse_normal;      // the pixel's first diffuse hit, w = material + 1
uniform sampler2D u_diffuse_throughput;
uniform int u_batch;
uniform int u_image_height;
uniform float u_total_rays;

ivec2 gather_texel(ivec2 px, int j) {
    return ivec2(px.x, px.y + j * u_image_height);
}

// throughput_1 x albedo_1 (the caller multiplies by the batch's sum and
// divides by u_total_rays, in that order), or false where the pixel has no
// first diffuse hit.
bool gather_weight(ivec2 px, out vec3 weight) {
    weight = vec3(0.0);
    int mat1 = int(texelFetch(u_diffuse_normal, px, 0).w) - 1;
    if (mat1 < 0) return false;
    weight = texelFetch(u_diffuse_throughput, px, 0).rgb * material_bsdf(mat1).color;
    return true;
}
