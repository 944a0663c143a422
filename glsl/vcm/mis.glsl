// Vertex connection and merging's MIS weights (Georgiev et al. 2012, with the
// recurrences of their SmallVCM; balance heuristic): the partial sums each
// subpath carries from vertex to vertex, as vec3(dVCM, dVC, dVM), and each
// technique's weight from them. src/twins/vcm.rs holds the same functions
// and tests that they are the balance heuristic over every technique's full
// path pdf, summing to 1. Pdfs are per unit solid angle (_w) or area (_a);
// Russian roulette's continuation probability is folded into each BSDF pdf.
// u_vm_factor = pi r^2 N when merging runs (else 0); u_vc_factor = its
// inverse when connections run (else 0); N = u_light_paths.

uniform float u_vm_factor;
uniform float u_vc_factor;
uniform float u_light_paths;
// Camera paths go on past a diffuse vertex with this fraction of the light
// paths' continuation probability there (`--camera-continuation`): each
// subpath's own probability enters the pdfs of the directions it samples.
uniform float u_camera_continuation;

// The camera path's continuation probability where a light path's is q.
float camera_continuation(float q) {
    return u_camera_continuation * q;
}

// A light subpath at its light: pick x area pdf of the point (pick for a
// point light), that x the direction's pdf, the cosine at the light.
vec3 mis_light_start(float direct_pdf_a, float emission_pdf_w, float cos_light, bool delta) {
    float d_vc = delta ? 0.0 : cos_light / emission_pdf_w;
    return vec3(direct_pdf_a / emission_pdf_w, d_vc, d_vc * u_vc_factor);
}

// A camera subpath at the camera: the eye ray's solid-angle pdf.
vec3 mis_camera_start(float camera_pdf_w) {
    return vec3(u_light_paths / camera_pdf_w, 0.0, 0.0);
}

// On arriving at a vertex `distance` away with cosine cos_in there (only the
// first hit from a light at infinity keeps its dVCM unscaled: scale_distance
// false; every light here is at a finite distance).
vec3 mis_arrive(vec3 p, float distance, float cos_in, bool scale_distance) {
    float d_vcm = scale_distance ? p.x * distance * distance : p.x;
    return vec3(d_vcm, p.y, p.z) / cos_in;
}

// On leaving a non-delta vertex by a sampled direction (cos_out there); the
// pdfs of the direction taken and of the reverse one.
vec3 mis_scatter(vec3 p, float cos_out, float dir_pdf_w, float rev_pdf_w) {
    float k = cos_out / dir_pdf_w;
    return vec3(1.0 / dir_pdf_w,
                k * (p.y * rev_pdf_w + p.x + u_vm_factor),
                k * (p.z * rev_pdf_w + p.x * u_vc_factor + 1.0));
}

// On leaving a mirror or glass: the pdfs cancel.
vec3 mis_scatter_specular(vec3 p, float cos_out) {
    return vec3(0.0, p.y * cos_out, p.z * cos_out);
}

// A camera path that hits an area light: the light's pick x area pdf of the
// point and that x the emitted direction's pdf.
float mis_emission_weight(vec3 camera, float direct_pdf_a, float emission_pdf_w) {
    return 1.0 / (1.0 + direct_pdf_a * camera.x + emission_pdf_w * camera.y);
}

// Next-event estimation at a camera vertex: the light sample's pick x
// solid-angle pdf at the vertex and pick x emission pdf, the cosines at the
// light and at the vertex, and the vertex BSDF's pdf toward the light (0 for
// a point light) and back toward the previous vertex.
float mis_light_sample_weight(vec3 camera, float direct_pdf_w, float emission_pdf_w,
                              float cos_light, float cos_vertex, float bsdf_dir_pdf_w,
                              float bsdf_rev_pdf_w) {
    float w_light = bsdf_dir_pdf_w / direct_pdf_w;
    float w_camera = emission_pdf_w * cos_vertex / (direct_pdf_w * cos_light)
                   * (u_vm_factor + camera.x + camera.y * bsdf_rev_pdf_w);
    return 1.0 / (w_light + 1.0 + w_camera);
}

// A light vertex connected to the camera: the area pdf with which the
// camera samples it, and its BSDF's reverse pdf.
float mis_camera_connection_weight(vec3 light, float camera_pdf_a, float bsdf_rev_pdf_w) {
    float w_light = camera_pdf_a / u_light_paths
                  * (u_vm_factor + light.x + light.y * bsdf_rev_pdf_w);
    return 1.0 / (w_light + 1.0);
}

// A camera vertex connected to a light vertex: for each end the area pdf
// with which the other end samples it, and its own reverse pdf.
float mis_vertex_connection_weight(vec3 camera, vec3 light, float camera_dir_pdf_a,
                                   float camera_rev_pdf_w, float light_dir_pdf_a,
                                   float light_rev_pdf_w) {
    float w_light = camera_dir_pdf_a * (u_vm_factor + light.x + light.y * light_rev_pdf_w);
    float w_camera = light_dir_pdf_a * (u_vm_factor + camera.x + camera.y * camera_rev_pdf_w);
    return 1.0 / (w_light + 1.0 + w_camera);
}

// A camera vertex merged with a light vertex: the camera BSDF's pdf of the
// light vertex's arriving direction reversed, and of its own reverse.
float mis_merge_weight(vec3 camera, vec3 light, float camera_dir_pdf_w, float camera_rev_pdf_w) {
    float w_light = light.x * u_vc_factor + light.z * camera_dir_pdf_w;
    float w_camera = camera.x * u_vc_factor + camera.z * camera_rev_pdf_w;
    return 1.0 / (w_light + 1.0 + w_camera);
}
