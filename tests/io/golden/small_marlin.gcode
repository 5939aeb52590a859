; rotomorph G-code (rotational multimaterial printing)
; tool: rotomorph 0.3.0
; design-sha256: 954abf4bacbdf3926504d0ad0b1acd518d70c069f1513a299f2d8958b17f0417
; machine: golden, built-in default (no machine profile given: its envelope and limits are assumptions; pass --machine FILE for your printer)
; controller: marlin
; limits: envelope [0.0, 0.0, 0.0]..[300.0, 300.0, 100.0] mm, feed 0.01..50 mm/s, rotation <= 40 rad/s (travel included), pressure 0..100 psi, lift 2 mm
; dialect: marlin, pressure idiom template
; units: length mm, feed mm/min, rotary deg, pressure psi, dwell ms
; axes: X=x Y=y Z=z (design z + z_offset 0 mm; Z 0 = substrate surface in the active work offset)
; rotary: C = nozzle angle of the active half, counter-clockwise from +x seen from above times sign +1
;   must read 0 with the active half toward +x at the start; cumulative within a filament, re-based with G92 between filaments (restored at the end), |C| <= 360 deg
; nozzle turns (physical): up to 1.1 in one filament (filament 0), 2.9 turned in all (travel included)
;   the nozzle winds up to 1.4 turns: the built-in default assumes a rotary union (continuous_rotation = true)
; pressure channels: active port 5, passive port 6
; filaments: 3, layers: 2, order: serpentine
; estimated print time: 124.6 s
G21
G90
; every pressure channel off before the first move (explicit states)
M42 P5 S0
M42 P6 S0
; layer 0
; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
; filament 0 turns the nozzle +1.06 times
G0 Z2.3 F1200
G0 X10 Y10 F1200
G1 Z0.3 C0 F1200
M42 P5 S76
M42 P6 S51
G4 P500
G1 X10.5 Y10 C95.492966 F180
G1 X11 Y10 C190.985932 F180
G1 X11.5 Y10 C286.478898 F180
G1 X12 Y10 C381.971863 F180
M42 P5 S0
M42 P6 S0
G4 P250
; end filament 0
; filament 1 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
; filament 1 turns the nozzle +0.00 times
G0 Z2.3 F1200
G0 X12 Y12 F1200
G92 C21.971863
G1 Z0.3 C151.35211 F1200
M42 P5 S64
M42 P6 S64
G1 X11.5 Y12 C151.35211 F90
G1 X11 Y12 C151.35211 F90
G1 X10.5 Y12 C151.35211 F90
G1 X10 Y12 C151.35211 F90
M42 P5 S0
M42 P6 S0
; end filament 1
G0 Z2.9 F1200
; UV cure after layer 0: 60 s by hand (no lamp commands in the machine profile): the program pauses (M0); switch the lamp on for 60 s, off, then resume
M0
; layer 1
; filament 2 layer=1 radius=0.3 active_fraction=1.0 active_material=lce passive_material=acrylate
; filament 2 turns the nozzle -1.06 times
G0 X10 Y10 F1200
G1 Z0.9 C0 F1200
M42 P5 S102
G1 X10.5 Y10 C-95.492966 F120
G1 X11 Y10 C-190.985932 F120
G1 X11.5 Y10 C-286.478898 F120
G1 X12 Y10 C-381.971863 F120
M42 P5 S0
; end filament 2
G0 Z2.9 F1200
; UV cure after layer 1: 60 s by hand (no lamp commands in the machine profile): the program pauses (M0); switch the lamp on for 60 s, off, then resume
M0
G92 C-21.971863
