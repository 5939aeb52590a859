; rotomorph G-code (rotational multimaterial printing)
; tool: rotomorph 0.3.0
; design-sha256: 954abf4bacbdf3926504d0ad0b1acd518d70c069f1513a299f2d8958b17f0417
; machine: golden, built-in default (no machine profile given: its envelope and limits are assumptions; pass --machine FILE for your printer)
; controller: a3200
; limits: envelope [0.0, 0.0, 0.0]..[300.0, 300.0, 100.0] mm, feed 0.01..50 mm/s, rotation <= 40 rad/s (travel included), pressure 0..100 psi, lift 2 mm
; dialect: aerotech, pressure idiom nordson
; units: length mm, feed mm/s, rotary deg, pressure psi, dwell s
; axes: X=x Y=y Z=z (design z + z_offset 0 mm; Z 0 = substrate surface in the active work offset)
; rotary: C = nozzle angle of the active half, counter-clockwise from +x seen from above times sign +1
;   must read 0 with the active half toward +x at the start; cumulative within a filament, re-based with G92 between filaments (restored at the end), |C| <= 360 deg
; nozzle turns (physical): up to 1.1 in one filament (filament 0), 2.9 turned in all (travel included)
;   the nozzle winds up to 1.4 turns: the built-in default assumes a rotary union (continuous_rotation = true)
; pressure channels: active port 5, passive port 6
; filaments: 3, layers: 2, order: serpentine
; estimated print time: 127.1 s
; rotomorph: variables of the pressure subroutines at the end of this program
DVAR $hFile $sum $k $frame $hex
G71
G76
G90
VELOCITY ON
; every pressure channel off before the first move (explicit states)
Call setDispense P5 Q0
Call setDispense P6 Q0
; layer 0
; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
; filament 0 turns the nozzle +1.06 times
G1 F20
G1 Z2.3
G1 X10 Y10
G1 Z0.3 C0
Call setPress P5 Q30
Call setDispense P5 Q1
Call setPress P6 Q20
Call setDispense P6 Q1
G4 P0.5
G1 F3
G1 X10.5 Y10 C95.492966
G1 X11 Y10 C190.985932
G1 X11.5 Y10 C286.478898
G1 X12 Y10 C381.971863
Call setDispense P5 Q0
Call setDispense P6 Q0
G4 P0.25
; end filament 0
; filament 1 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
; filament 1 turns the nozzle +0.00 times
G1 F20
G1 Z2.3
G1 X12 Y12
G92 C21.971863
G1 Z0.3 C151.35211
Call setPress P5 Q25
Call setDispense P5 Q1
Call setPress P6 Q25
Call setDispense P6 Q1
G1 F1.5
G1 X11.5 Y12 C151.35211
G1 X11 Y12 C151.35211
G1 X10.5 Y12 C151.35211
G1 X10 Y12 C151.35211
Call setDispense P5 Q0
Call setDispense P6 Q0
; end filament 1
G1 F20
G1 Z2.9
; UV cure after layer 0: 60 s by hand (no lamp commands in the machine profile): the program pauses (M0); switch the lamp on for 60 s, off, then resume
M0
; layer 1
; filament 2 layer=1 radius=0.3 active_fraction=1.0 active_material=lce passive_material=acrylate
; filament 2 turns the nozzle -1.06 times
G1 X10 Y10
G1 Z0.9 C0
Call setPress P5 Q40
Call setDispense P5 Q1
G1 F2
G1 X10.5 Y10 C-95.492966
G1 X11 Y10 C-190.985932
G1 X11.5 Y10 C-286.478898
G1 X12 Y10 C-381.971863
Call setDispense P5 Q0
; end filament 2
G1 F20
G1 Z2.9
; UV cure after layer 1: 60 s by hand (no lamp commands in the machine profile): the program pauses (M0); switch the lamp on for 60 s, off, then resume
M0
G92 C-21.971863
M2
; rotomorph: pressure subroutines called above (P = COM port, Q = value); serial
; settings 115200 baud 8N1: change them here if your regulators differ
; rotomorph: pressure set-point in psi (the Ultimus takes tenths of a psi, 4 digits)
DFS setPress
    $k = ROUND($Q * 10)
    $hex = DBLTOSTR($k, 0)
    WHILE STRLEN($hex) < 4
        $hex = "0" + $hex
    ENDWHILE
    $hFile = FILEOPEN "COM" + DBLTOSTR($P, 0), 2
    COMMINIT $hFile, "baud=115200 parity=N data=8 stop=1"
    COMMSETTIMEOUT $hFile, -1, -1, 1000
    $frame = "08PS  " + $hex
    $sum = 0
    FOR $k = 0 TO STRLEN($frame) - 1
        $sum = $sum + STRTOASCII($frame, $k)
    NEXT $k
    $sum = (256 - ($sum % 256)) % 256
    $hex = STRUPR(MAKESTRING "{#H}" $sum)
    IF STRLEN($hex) < 2 THEN
        $hex = "0" + $hex
    ENDIF
    FILEWRITE $hFile "\x05"
    FILEWRITE $hFile "\x02" + $frame + $hex + "\x03"
    FILEWRITE $hFile "\x04"
    FILECLOSE $hFile
ENDDFS
; rotomorph: dispense (Q1) or stop (Q0); the port's last state is kept in $global[P]
DFS setDispense
    IF $global[$P] <> $Q THEN
        $hFile = FILEOPEN "COM" + DBLTOSTR($P, 0), 2
        COMMINIT $hFile, "baud=115200 parity=N data=8 stop=1"
        COMMSETTIMEOUT $hFile, -1, -1, 1000
        $frame = "04DI  "
        $sum = 0
        FOR $k = 0 TO STRLEN($frame) - 1
            $sum = $sum + STRTOASCII($frame, $k)
        NEXT $k
        $sum = (256 - ($sum % 256)) % 256
        $hex = STRUPR(MAKESTRING "{#H}" $sum)
        IF STRLEN($hex) < 2 THEN
            $hex = "0" + $hex
        ENDIF
        FILEWRITE $hFile "\x05"
        FILEWRITE $hFile "\x02" + $frame + $hex + "\x03"
        FILEWRITE $hFile "\x04"
        FILECLOSE $hFile
        $global[$P] = $Q
    ENDIF
ENDDFS
