// One object drawn with one environment-map shell (appended to shell.wgsl): the pipeline
// that the hardware model's shell render matrices are checked against and that probe-style
// renderings use. The fragment is `fs_shell`, the twin of pis-compile's
// `shell::model::shell_render_matrix`.

struct ShellUniforms {
    // projection · view · world of the object.
    clip_from_object: mat4x4<f32>,
    // world of the object (rigid).
    world_from_object: mat4x4<f32>,
    // The camera's position (xyz).
    eye: vec4<f32>,
    // The shell's origin (xyz) and shape id (w).
    origin_shape: vec4<f32>,
    a: vec4<f32>,
    b: vec4<f32>,
    // Face size N, MIP level count, lookups per pixel side.
    size: u32,
    levels: u32,
    lookups: u32,
    _pad: u32,
};

@group(0) @binding(0) var<uniform> su: ShellUniforms;
@group(0) @binding(1) var cube: texture_2d_array<f32>;
// A depth shell's depth cube (one level, bordered; a 1-texel stand-in for other shapes).
@group(0) @binding(2) var depth_cube: texture_2d_array<f32>;

struct ShellVsOut {
    @builtin(position) clip: vec4<f32>,
    // World position and normal, interpolated perspective-correct.
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

fn shell_geometry() -> ShellGeometry {
    return ShellGeometry(su.origin_shape.xyz, u32(su.origin_shape.w), su.a.xyz, su.b.xyz);
}

@vertex
fn vs_shell(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> ShellVsOut {
    var out: ShellVsOut;
    out.clip = su.clip_from_object * vec4<f32>(position, 1.0);
    out.world = (su.world_from_object * vec4<f32>(position, 1.0)).xyz;
    out.normal = (su.world_from_object * vec4<f32>(normal, 0.0)).xyz;
    return out;
}

// Depth-only pass of the occluders.
@vertex
fn vs_shell_depth(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return su.clip_from_object * vec4<f32>(position, 1.0);
}

@fragment
fn fs_shell(in: ShellVsOut) -> @location(0) vec4<f32> {
    let c = cube_sample_pixel(shell_geometry(), cube, depth_cube, su.size, su.levels, su.lookups, su.eye.xyz, in.world, in.normal);
    // Alpha 1 marks coverage.
    return vec4<f32>(c.rgb, 1.0);
}

// The depth-only pass writes no colour (its target's write mask is empty).
@fragment
fn fs_shell_depth() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}
