; rotomorph G-code (rotational multimaterial printing)
; tool: rotomorph 0.1.0
; design-sha256: 954abf4bacbdf3926504d0ad0b1acd518d70c069f1513a299f2d8958b17f0417
; machine: golden, built-in default (no machine profile given: its envelope and limits are assumptions; pass --machine FILE for your printer)
; limits: envelope [0.0, 0.0, 0.0]..[300.0, 300.0, 100.0] mm, feed 0.01..50 mm/s, rotation <= 40 rad/s, pressure 0..100 psi, travel lift 2 mm
; dialect: marlin
; units: length mm, feed mm/min, rotary deg, pressure psi
; axes: X=x Y=y Z=z C=nozzle angle (sign +1, ccw from +x seen from above), cumulative
; pressure channels: active port 5, passive port 6
; filaments: 3, layers: 2
; estimated print time: 1203.7 s
G21
G90
; layer 0
; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3
G0 X10 Y10 C0
G0 Z0.3
M800 P5 Q30.000
M800 P6 Q20.000
G1 X10.5 Y10 C95.492966 F180
G1 X11 Y10 C190.985932 F180
G1 X11.5 Y10 C286.478898 F180
G1 X12 Y10 C381.971863 F180
M800 P5 Q0.000
M800 P6 Q0.000
; end filament 0
; filament 1 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3
G0 X10 Y12 C28.64789
G0 Z0.3
M800 P5 Q25.000
M800 P6 Q25.000
G1 X10.5 Y12 C28.64789 F90
G1 X11 Y12 C28.64789 F90
G1 X11.5 Y12 C28.64789 F90
G1 X12 Y12 C28.64789 F90
M800 P5 Q0.000
M800 P6 Q0.000
; end filament 1
; UV cure after layer 0: 600 s
G4 S600
; layer 1
; filament 2 layer=1 radius=0.3 active_fraction=1.0 active_material=lce passive_material=acrylate
G0 Z2.9
G0 X10 Y10 C0
G0 Z0.9
M800 P5 Q40.000
M800 P6 Q0.000
G1 X10.5 Y10 C-95.492966 F120
G1 X11 Y10 C-190.985932 F120
G1 X11.5 Y10 C-286.478898 F120
G1 X12 Y10 C-381.971863 F120
M800 P5 Q0.000
M800 P6 Q0.000
; end filament 2
; UV cure after layer 1: 600 s
G4 S600
G0 Z2.9
